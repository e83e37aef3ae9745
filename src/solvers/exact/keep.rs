//! The engine `exact` keeps between steps ([`EngineState`], also what a checkpoint stores of
//! it) and how the continuous step gathers the circles into it: kept as it is when nothing
//! outside touched them, updated for the few that user code moved, steered or turned
//! ([`super::outside`]), rebuilt otherwise (and under `swept` in every step where something
//! moves), rough when the effects say so.

use bevy::ecs::entity::{EntityHashMap, EntityHashSet};
use bevy::math::DVec2;
use bevy::prelude::*;

use super::engine::{EngineSnapshot, EventEngine, EventStats, Rest, Roughness};
use super::outside::{moved_since, turning_of};
use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::collision_layers::CircleFilters;
use crate::base::components::{
    AngularVelocity, Inertia, Mass, Position, Radius, Restitution, Rotation, Sleep, SolverCircles,
    SpinCircles, Velocity,
};
use crate::base::config::{Effects, Solver};
use crate::base::order::CircleOrder;
use crate::base::segment::Segments;
use crate::step::bodies::{BodyStore, GatherOwn};
use crate::step::schedule::StopRequest;

/// `exact` updates its engine in place when at most one circle in this many was moved from
/// outside since the last step, and rebuilds it when more were (each update costs about what a
/// collision does; a rebuild, what `N` of them do).
const MOVED_FOR_REBUILD: usize = 4;

/// The engine kept between `exact` steps, with the entities of its circles (in serial order,
/// [`CircleOrder`], when it was built) and, once a step needs it, each one's index.
#[derive(Resource, Default, Clone)]
pub struct EngineState {
    pub(super) engine: Option<EventEngine>,
    pub(super) entities: Vec<Entity>,
    pub(super) index: EntityHashMap<usize>,
    /// Whether a stop request ended the last step early: its engine flew the circles to the
    /// step's end without predicting again ([`EventEngine::fly_unpredicted_to`]), so it is not
    /// kept and the next step, if any, rebuilds.
    pub(super) stopped: bool,
    pub(super) setup: Option<(Arena, Effects, Solver)>,
    /// The segment walls the engine was built with.
    pub(super) segments: Segments,
    pub(super) last_stats: EventStats,
    /// Steps whose event budget ran out (their remainder was free flight).
    pub budget_exhausted: u64,
    /// Times the engine was rebuilt from the ECS state.
    pub rebuilds: u64,
    /// Steps in which the kept engine was updated for a few circles moved from outside.
    pub updates: u64,
}

impl EngineState {
    /// The `exact` engine kept for the next step, as data for a checkpoint of `circles` (the
    /// world's now, with their entities in the order of the step's query) under `setup` (the
    /// world's arena, effects and solver) and `segments`. What user code wrote to the circles
    /// since the last step is applied as that step's gather would apply it, so the checkpoint's
    /// engine and circles agree. `None` under the other solvers, which keep nothing between
    /// steps; where the next step would build a fresh engine (the setup or the segment walls
    /// changed, circles came, went or changed their radius or mass, or more than one in
    /// `MOVED_FOR_REBUILD` was moved); and while circles meet nothing (sensors): its cells
    /// are sized without them. The resumed run then builds its engine afresh from the state,
    /// as the next step would (and where circles have layers, which a restored engine lacks).
    pub fn snapshot(
        &self,
        setup: (Arena, Effects, Solver),
        segments: &Segments,
        circles: &[(Entity, CircleState)],
    ) -> Option<EngineSnapshot> {
        let engine = self.engine.as_ref()?;
        let kept = self.setup == Some(setup)
            && setup.2 == Solver::Exact
            && self.segments == *segments
            && !self.stopped
            && engine.cells_sized_for_all()
            && circles.len() == self.entities.len()
            && circles.iter().zip(&self.entities).all(|((e, _), k)| e == k);
        if !kept {
            return None;
        }
        let mut moved = Vec::new();
        for (i, (_, c)) in circles.iter().enumerate() {
            let (radius, inv_mass, _) = engine.body(i);
            if (radius, inv_mass) != (c.radius, c.inv_mass()) {
                return None;
            }
            let motion = (c.position, c.velocity) != (engine.position(i), engine.velocity(i));
            let turn = (c.angular_velocity, c.rotation);
            let turned = engine.turn(i).is_some_and(|t| t != turn);
            if motion || turned {
                moved.push((
                    i,
                    motion.then_some((c.position, c.velocity)),
                    turned.then_some(turn),
                ));
            }
        }
        if moved.is_empty() {
            return Some(engine.snapshot());
        }
        if moved.len() > circles.len() / MOVED_FOR_REBUILD {
            return None;
        }
        let mut engine = engine.clone();
        for (i, motion, turn) in moved {
            if let Some((position, velocity)) = motion {
                engine.set_motion(i, position, velocity);
            }
            if let Some((spin, angle)) = turn {
                engine.set_turn(i, spin, angle);
            }
        }
        Some(engine.snapshot())
    }

    /// Puts back the `exact` engine of a checkpoint for `circles` (entities in query order,
    /// states as the engine last wrote them) under the world's arena, effects, segment walls and
    /// restitutions (each circle's, if any has its own), so the next step goes on with it.
    pub fn restore(
        &mut self,
        snapshot: EngineSnapshot,
        circles: &[(Entity, CircleState)],
        (arena, effects, segments, restitutions): (Arena, Effects, &Segments, Vec<f64>),
    ) -> Result<(), String> {
        let states: Vec<CircleState> = circles.iter().map(|&(_, c)| c).collect();
        let mut engine = EventEngine::restore(
            snapshot,
            &states,
            &arena,
            &segments.0,
            (effects.restitution, effects.wall_restitution),
            effects.gravity.unwrap_or_default(),
            roughness(&effects),
            effects.collisions,
        )?;
        engine.record_hits(effects.hit_messages);
        engine.set_own_restitutions(restitutions);
        if let Some(i) = (0..engine.len()).find(|&i| engine.position(i) != states[i].position) {
            return Err(format!(
                "engine state of circle {i} puts it elsewhere than the circle"
            ));
        }
        self.last_stats = engine.stats();
        self.engine = Some(engine);
        self.know(circles.iter().map(|&(e, _)| e).collect());
        self.setup = Some((arena, effects, Solver::Exact));
        self.segments = segments.clone();
        Ok(())
    }

    /// Takes the circles `entities` (in serial order, the engine's) as the engine's, where a
    /// rollback put back an engine saved with other entities for the same circles.
    pub(crate) fn rekey(&mut self, entities: &[Entity]) {
        if self.entities != entities {
            self.entities.clear();
            self.entities.extend_from_slice(entities);
            self.index.clear();
        }
    }

    /// Takes `entities` as the engine's circles, in index order.
    fn know(&mut self, entities: Vec<Entity>) {
        self.index.clear();
        self.entities = entities;
        self.stopped = false;
    }
}

/// The circles anything but [`continuous_step`] wrote to since that system last ran (or that
/// were spawned since): the only ones it looks at closely when it keeps its engine.
pub(super) type ChangedCircles<'w, 's> = Query<
    'w,
    's,
    Entity,
    (
        With<Position>,
        With<Velocity>,
        With<Radius>,
        With<Mass>,
        Or<(
            Changed<Position>,
            Changed<Velocity>,
            Changed<Radius>,
            Changed<Mass>,
            Changed<Restitution>,
        )>,
    ),
>;

/// The circles whose turning anything but [`continuous_step`] wrote to since it last ran: only
/// a rough engine looks at them (a query of their own, so a smooth one pays nothing for it).
pub(super) type TurnedCircles<'w, 's> = Query<
    'w,
    's,
    Entity,
    (
        With<Radius>,
        Or<(
            Changed<AngularVelocity>,
            Changed<Rotation>,
            Changed<Inertia>,
        )>,
    ),
>;

/// The circles whose [`Sleep`] anything but [`continuous_step`] wrote to since it last ran (a
/// user waking a circle or putting it to sleep, everyone woken by a change of the effects, or
/// a checkpoint put back).
pub(super) type ResleptCircles<'w, 's> = Query<'w, 's, (), (With<Radius>, Changed<Sleep>)>;

/// The circles as the step sees them, one view at a time: all, changed, sleep, spin, turned,
/// their sleep written from outside.
pub(super) type EngineViews = (
    SolverCircles<'static, 'static>,
    ChangedCircles<'static, 'static>,
    Query<'static, 'static, &'static mut Sleep>,
    SpinCircles<'static, 'static>,
    TurnedCircles<'static, 'static>,
    ResleptCircles<'static, 'static>,
);

/// What circles have of their own beyond their motion, as the continuous step gathers it.
pub(super) struct Own<'a> {
    /// Whether a circle lost its own restitution, moment of inertia, layers or sensor since
    /// the last step, or had its layers set or changed or became a sensor (a kept engine cannot
    /// tell).
    pub lost: bool,
    /// Whether any circle has its own restitution.
    pub restitution: bool,
    /// Each circle's layers.
    pub filters: &'a CircleFilters<'a, 'a>,
    /// Whether a circle's [`Sleep`] was written from outside since the last step (a user
    /// waking it or putting it to sleep; everyone woken by a change of the effects).
    pub slept: bool,
}

/// Keeps the `exact` engine if nothing but the engine itself changed the circles since the last
/// step; updates it if user code moved or steered a few of them (a teleport, a kinematic
/// paddle); otherwise builds a fresh one from the circles, with their own restitutions and
/// layers. `swept` keeps its engine only while nothing in it moves and nothing outside touched
/// a circle, and builds a fresh one otherwise. Says which in a debug log. A build that `stop`
/// ends leaves no engine: the step then moves nothing and counts in `budget_exhausted`.
pub(super) fn gather_into_engine(
    (setup, order, stop): (
        (Solver, Arena, Effects, &Segments),
        &CircleOrder,
        Option<&StopRequest>,
    ),
    state: &mut EngineState,
    own: Own,
    circles: &mut ParamSet<EngineViews>,
) {
    let (solver, arena, effects, segments) = setup;
    let key = (arena, effects, solver);
    let restitution_of = |own: Option<&Restitution>| own.map_or(effects.restitution, |e| e.0);
    // `swept` keeps only an engine in which nothing moves (a pile asleep) and no circle was
    // moved, steered, turned (a sleeper set turning wakes) or woken from outside: a fresh one
    // would be the same, and would come to the same end of the step.
    let kept = match (&state.engine, solver) {
        (None, _) => false,
        (Some(engine), Solver::Swept) => {
            !own.slept && engine.is_still() && circles.p1().is_empty() && circles.p4().is_empty()
        }
        (Some(_), _) => true,
    };
    let reason = match (&mut state.engine, solver) {
        (Some(_), _) if kept && own.lost => {
            "a circle lost its restitution or moment of inertia, or its layers changed"
        }
        (Some(_), _) if kept && state.stopped => "a stop request ended the last step early",
        (Some(engine), _) if kept && state.setup == Some(key) && state.segments == *segments => {
            let mut changed: Vec<Entity> = circles.p1().iter().collect();
            let turned = match engine.roughness().is_smooth() {
                true => Vec::new(),
                false => {
                    // A rough engine also hears circles turned from outside.
                    let moved: EntityHashSet = changed.iter().copied().collect();
                    let turned = circles.p4();
                    changed.extend(turned.iter().filter(|e| !moved.contains(e)));
                    turning_of(&circles.p3(), changed.iter().copied())
                }
            };
            let all = circles.p0();
            // Built the first time a kept engine needs it, so `swept` (which keeps an engine
            // only while nothing moves or is touched) never does.
            if !changed.is_empty() && state.index.is_empty() {
                let entities = state.entities.iter().enumerate();
                state.index = entities.map(|(i, &e)| (e, i)).collect();
            }
            let known = (state.entities.len(), &state.index);
            let changed = (&changed[..], &turned[..]);
            match moved_since(engine, known, changed, &all, restitution_of) {
                Ok(moved) if moved.is_empty() => return,
                Ok(mut moved) if moved.len() <= all.iter().len() / MOVED_FOR_REBUILD => {
                    // In the engine's order, whichever order change detection found them in
                    // (turned-only circles come last), as a checkpoint's engine applies them.
                    moved.sort_unstable_by_key(|m| m.index);
                    for m in &moved {
                        if let Some((position, velocity)) = m.motion {
                            engine.set_motion(m.index, position, velocity);
                        }
                        if let Some((spin, angle)) = m.turn {
                            engine.set_turn(m.index, spin, angle);
                        }
                    }
                    let n = moved.len();
                    debug!("exact engine: updated {n} circle(s) moved from outside");
                    state.updates += 1;
                    return;
                }
                Ok(_) => "most circles were changed from outside (a force effect)",
                Err(reason) => reason,
            }
        }
        (_, Solver::Exact) => "new solver, arena, segment walls or effects",
        _ => "swept builds every step something moves",
    };
    if solver == Solver::Exact {
        debug!("exact engine: rebuilt ({reason})");
    }
    // Millions of circles take seconds to gather and build: a stop request is heard between
    // tables. Stopped before every circle was predicted, this step moves nothing.
    let stopped = || stop.is_some_and(StopRequest::raised);
    let give_up = |state: &mut EngineState| {
        debug!("exact engine: build stopped by a stop request");
        state.engine = None;
        state.setup = None;
        state.budget_exhausted += 1;
    };
    // A sleeper your code set moving or turning since the last step wakes, as under the
    // time-stepped solvers (built asleep, it would lose the velocity).
    let rest_of = |sleep: &Sleep, moving: bool| match sleep.asleep && moving {
        true => Rest::default(),
        false => Rest {
            asleep: sleep.asleep,
            anchor: sleep.anchor,
            resting_for: sleep.slow_for,
        },
    };
    let mut store = BodyStore::default();
    let mut sleeps = Vec::with_capacity(order.entities().len());
    let gather = GatherOwn {
        restitution: own.restitution.then_some(effects.restitution),
        filters: own.filters,
    };
    store.gather(order, &circles.p0(), &gather, |_, sleep| {
        sleeps.push(*sleep)
    });
    if stopped() {
        return give_up(state);
    }
    let BodyStore {
        entity: entities,
        position,
        velocity,
        radius,
        mass,
        restitution: own_restitutions,
        layers,
        ..
    } = store;
    let bodies: Vec<CircleState> = (0..entities.len())
        .map(|i| CircleState::new(position[i], velocity[i], radius[i]).with_mass(mass[i]))
        .collect();
    let mut rest: Vec<Rest> = sleeps
        .iter()
        .zip(&velocity)
        .map(|(sleep, &v)| rest_of(sleep, v != DVec2::ZERO))
        .collect();
    let spins = circles.p3();
    for (r, &e) in rest.iter_mut().zip(&entities).filter(|(r, _)| r.asleep) {
        if let Ok((Some(spin), ..)) = spins.get(e)
            && spin.0 != 0.0
        {
            *r = Rest::default();
        }
    }
    let restitutions = (effects.restitution, effects.wall_restitution);
    let fall = (effects.gravity, &rest[..]);
    let Some(mut engine) = EventEngine::build_until(
        &bodies,
        &arena,
        &segments.0,
        restitutions,
        fall,
        layers,
        stopped,
    ) else {
        return give_up(state);
    };
    // Without the collisions effect circles pass through each other (they still hit walls).
    engine.set_pairs(effects.collisions);
    if own.restitution {
        engine.set_own_restitutions(own_restitutions);
    }

    if effects.is_rough() {
        let turning = turning_of(&circles.p3(), entities.iter().copied());
        engine.make_rough(roughness(&effects), turning.iter().map(|t| t.turn));
        if turning.iter().any(|t| t.inertia.is_some()) {
            engine.set_own_inertias(turning.iter().map(|t| t.inertia).collect());
        }
    }
    engine.record_hits(effects.hit_messages);
    state.last_stats = engine.stats();
    state.engine = Some(engine);
    state.know(entities);
    state.setup = Some(key);
    if state.segments != *segments {
        state.segments = segments.clone();
    }
    state.rebuilds += 1;
}

/// The roughness of hits `effects` call for.
pub(super) fn roughness(effects: &Effects) -> Roughness {
    Roughness {
        circles: effects.tangential_restitution,
        walls: effects.wall_tangential_restitution,
    }
}
