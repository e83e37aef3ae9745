//! The continuous solvers, `swept` and `exact`, built on one event-driven [`engine`]:
//! - `exact` keeps one engine alive across steps (cost per collision, not per step) and only
//!   rebuilds it when something outside changed the circles (a respawn, a drag with the mouse,
//!   a force effect, a solver switch);
//! - `swept` builds a fresh engine from the current state every step and resolves that step's
//!   hits in time order, with a bounded number of events per step ([`SWEPT_EVENTS_PER_CIRCLE`]);
//!   past the bound the rest of the step is free flight and the missed hits resolve next step.
//!
//! Both handle walls, periodic edges and collisions themselves, so they run in the
//! [`ContinuousStep`] schedule after the force effects, as one system in three parts: gather the
//! circles into the engine (rebuilding it if needed), advance it by the step, write the circles
//! back. One system, so that its change filters see only what others wrote since its last
//! write-back: a step where nothing outside touched the circles pays for its events, Bevy's
//! change-tick check and one write per circle, not for comparing every circle's values.

pub mod engine;
pub mod fall;
pub mod pack;
pub mod queue;
pub mod roots;
pub mod toi;

use bevy::ecs::entity::EntityHashMap;
use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::arena::Arena;
use crate::boundary::WallCollisions;
use crate::circle::CircleState;
use crate::collide::PairCollisions;
use crate::components::{
    Mass, Position, Radius, Restitution, Sleep, SolverCircles, SpinCircles, Velocity,
};
use crate::config::{Effects, Solver};
use crate::hits::{CircleHit, WallHit};
use crate::integrate::turn_circles;
use crate::schedule::{CircleSystems, ContinuousStep, StepDt, StopRequest};
use crate::segment::Segments;
use crate::sleep::Sleeping;
use engine::{EngineSnapshot, EventEngine, EventStats, Rest};

/// Events a `swept` step may process per circle before the rest of the step is free flight.
pub const SWEPT_EVENTS_PER_CIRCLE: u64 = 64;
/// The same bound for `exact`, high enough to be reached only by inelastic collapse.
pub const EXACT_EVENTS_PER_CIRCLE: u64 = 100_000;
/// `exact` updates its engine in place when at most one circle in this many was moved from
/// outside since the last step, and rebuilds it when more were (each update costs about what a
/// collision does; a rebuild, what `N` of them do).
const MOVED_FOR_REBUILD: usize = 4;

/// Adds the `swept` / `exact` step to [`ContinuousStep`].
#[derive(Clone, Copy, Debug, Default)]
pub struct ContinuousPlugin;

impl Plugin for ContinuousPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<EngineState>()
            .init_resource::<Segments>()
            .init_resource::<PairCollisions>()
            .init_resource::<WallCollisions>()
            .add_message::<CircleHit>()
            .add_message::<WallHit>()
            .add_systems(
                ContinuousStep,
                continuous_step.in_set(CircleSystems::Continuous),
            );
    }
}

/// The engine kept between `exact` steps, with the entities of its circles (in the order of
/// [`SolverCircles`] when it was built) and, once a step needs it, each one's index.
#[derive(Resource, Default)]
pub struct EngineState {
    engine: Option<EventEngine>,
    entities: Vec<Entity>,
    index: EntityHashMap<usize>,
    /// Whether the last write-back found the circles in another order than `entities` (an
    /// entity moved between archetypes), so the next step rebuilds.
    reordered: bool,
    setup: Option<(Arena, Effects, Solver)>,
    /// The segment walls the engine was built with.
    segments: Segments,
    last_stats: EventStats,
    /// Steps whose event budget ran out (their remainder was free flight).
    pub budget_exhausted: u64,
    /// Times the engine was rebuilt from the ECS state.
    pub rebuilds: u64,
    /// Steps in which the kept engine was updated for a few circles moved from outside.
    pub updates: u64,
}

impl EngineState {
    /// The `exact` engine kept for the next step, as data for a checkpoint (`None` under the
    /// other solvers, which keep nothing between steps).
    pub fn snapshot(&self) -> Option<EngineSnapshot> {
        match self.setup {
            Some((_, _, Solver::Exact)) => self.engine.as_ref().map(EventEngine::snapshot),
            _ => None,
        }
    }

    /// Puts back the `exact` engine of a checkpoint for `circles` (entities in the order of the
    /// continuous step's query, states as the engine last wrote them), so that the next step
    /// goes on with it instead of rebuilding.
    pub fn restore(
        &mut self,
        snapshot: EngineSnapshot,
        circles: &[(Entity, CircleState)],
        setup: (Arena, Effects, &Segments),
    ) -> Result<(), String> {
        let (arena, effects, segments) = setup;
        let states: Vec<CircleState> = circles.iter().map(|&(_, c)| c).collect();
        let mut engine = EventEngine::restore(
            snapshot,
            &states,
            &arena,
            &segments.0,
            (effects.restitution, effects.wall_restitution),
            effects.gravity.unwrap_or_default(),
        )?;
        engine.record_hits(effects.hit_messages);
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

    /// Takes `entities` as the engine's circles, in index order.
    fn know(&mut self, entities: Vec<Entity>) {
        self.index.clear();
        self.entities = entities;
        self.reordered = false;
    }
}

/// The circles anything but [`continuous_step`] wrote to since that system last ran (or that
/// were spawned since): the only ones it looks at closely when it keeps its engine.
type ChangedCircles<'w, 's> = Query<
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

/// The circles as the step sees them, one view at a time: all, changed, sleep, spin.
type EngineViews = (
    SolverCircles<'static, 'static>,
    ChangedCircles<'static, 'static>,
    Query<'static, 'static, &'static mut Sleep>,
    SpinCircles<'static, 'static>,
);

/// What the continuous step counts: hits of each kind, and the circles asleep.
#[derive(SystemParam)]
struct Counted<'w> {
    pairs: ResMut<'w, PairCollisions>,
    walls: ResMut<'w, WallCollisions>,
    sleeping: ResMut<'w, Sleeping>,
}

/// What the engine is built for and how far a step takes it.
#[derive(SystemParam)]
struct StepSetup<'w> {
    solver: Res<'w, Solver>,
    arena: Res<'w, Arena>,
    effects: Res<'w, Effects>,
    segments: Res<'w, Segments>,
    dt: Res<'w, StepDt>,
    stop: Option<Res<'w, StopRequest>>,
}

/// The `swept` / `exact` step: gathers the circles into the engine, advances it by the step and
/// writes the circles back (see the module docs for why this is one system).
fn continuous_step(
    setup: StepSetup,
    mut state: ResMut<EngineState>,
    own_restitution: Query<(), With<Restitution>>,
    mut lost_restitution: RemovedComponents<Restitution>,
    mut circles: ParamSet<EngineViews>,
    mut counted: Counted,
    messages: (MessageWriter<CircleHit>, MessageWriter<WallHit>),
) {
    let StepSetup {
        solver,
        arena,
        effects,
        segments,
        dt,
        stop,
    } = setup;
    let restitution_lost = !lost_restitution.is_empty();
    lost_restitution.clear();
    let with_own_restitution = !own_restitution.is_empty();
    gather_into_engine(
        ((*solver, *arena, *effects, &segments), stop.as_deref()),
        &mut state,
        (restitution_lost, with_own_restitution),
        &mut circles,
    );
    advance_engine(
        (*solver, dt.0, stop.as_deref()),
        &mut state,
        (&mut counted.pairs, &mut counted.walls),
        messages,
    );
    write_back(&mut state, &mut circles.p0());
    counted.sleeping.count = write_back_sleep(&state, &mut circles.p2());
    turn_circles(&mut circles.p3(), dt.0); // smooth circles trade no spin
}

/// Writes each circle's rest back to its [`Sleep`] (in the engine's order), for the next engine
/// `swept` builds and for checkpoints, and returns how many circles sleep. Only under gravity:
/// without it nothing rests.
fn write_back_sleep(state: &EngineState, sleep: &mut Query<&mut Sleep>) -> usize {
    let Some(engine) = state.engine.as_ref() else {
        return 0;
    };
    let falling = matches!(state.setup, Some((_, effects, _)) if effects.gravity.is_some());
    if !falling {
        return 0;
    }
    let mut asleep = 0;
    for (i, &entity) in state.entities.iter().enumerate() {
        let rest = engine.rest(i);
        asleep += usize::from(rest.asleep);
        let now = Sleep {
            anchor: rest.anchor,
            slow_for: rest.resting_for,
            asleep: rest.asleep,
        };
        if let Ok(mut s) = sleep.get_mut(entity)
            && *s != now
        {
            *s = now;
        }
    }
    asleep
}

/// Keeps the `exact` engine if nothing but the engine itself changed the circles since the last
/// step; updates it if user code moved or steered a few of them (a teleport, a kinematic
/// paddle); otherwise (and always for `swept`) builds a fresh one from the circles. Says which
/// in a debug log. `restitution` says whether a circle lost its own restitution since the last
/// step, and whether any has one. A build that `stop` ends leaves no engine: the step then
/// moves nothing and counts in `budget_exhausted`.
fn gather_into_engine(
    (setup, stop): ((Solver, Arena, Effects, &Segments), Option<&StopRequest>),
    state: &mut EngineState,
    restitution: (bool, bool),
    circles: &mut ParamSet<EngineViews>,
) {
    let (solver, arena, effects, segments) = setup;
    let (restitution_lost, with_own_restitution) = restitution;
    let key = (arena, effects, solver);
    let restitution_of = |own: Option<&Restitution>| own.map_or(effects.restitution, |e| e.0);
    let reason = match (&mut state.engine, solver) {
        (Some(_), Solver::Exact) if restitution_lost => "a circle lost its restitution",
        (Some(_), Solver::Exact) if state.reordered => "circles moved between archetypes",
        (Some(engine), Solver::Exact)
            if state.setup == Some(key) && state.segments == *segments =>
        {
            let changed: Vec<Entity> = circles.p1().iter().collect();
            let all = circles.p0();
            // Built the first time a kept engine needs it, so `swept` (which builds an engine
            // every step) never does.
            if !changed.is_empty() && state.index.is_empty() {
                let entities = state.entities.iter().enumerate();
                state.index = entities.map(|(i, &e)| (e, i)).collect();
            }
            let known = (state.entities.len(), &state.index);
            match moved_since(engine, known, &changed, &all, restitution_of) {
                Ok(moved) if moved.is_empty() => return,
                Ok(moved) if moved.len() <= all.iter().len() / MOVED_FOR_REBUILD => {
                    for &(i, position, velocity) in &moved {
                        engine.set_motion(i, position, velocity);
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
        _ => "swept builds every step",
    };
    if solver == Solver::Exact {
        debug!("exact engine: rebuilt ({reason})");
    }
    let all = circles.p0();
    let bodies: Vec<CircleState> = all
        .iter()
        .map(|(_, p, v, r, m, ..)| CircleState::new(p.0, v.0, r.0).with_mass(m.0))
        .collect();
    let rest: Vec<Rest> = all
        .iter()
        .map(|c| Rest {
            asleep: c.6.asleep,
            anchor: c.6.anchor,
            resting_for: c.6.slow_for,
        })
        .collect();
    let restitutions = (effects.restitution, effects.wall_restitution);
    let stopped = || stop.is_some_and(StopRequest::raised);
    let fall = (effects.gravity, &rest[..]);
    let Some(mut engine) =
        EventEngine::build_until(&bodies, &arena, &segments.0, restitutions, fall, stopped)
    else {
        // Stopped before every circle was predicted: this step moves nothing, and the next
        // one builds again.
        debug!("exact engine: build stopped by a stop request");
        state.engine = None;
        state.setup = None;
        state.budget_exhausted += 1;
        return;
    };
    if with_own_restitution {
        engine.set_own_restitutions(all.iter().map(|c| restitution_of(c.5)).collect());
    }
    engine.record_hits(effects.hit_messages);
    state.last_stats = engine.stats();
    state.engine = Some(engine);
    state.know(all.iter().map(|(e, ..)| e).collect());
    state.setup = Some(key);
    if state.segments != *segments {
        state.segments = segments.clone();
    }
    state.rebuilds += 1;
}

/// Of the `changed` circles (written since the kept `engine` last wrote them, or spawned), those
/// user code moved or steered (index, new position and velocity); or why the engine cannot be
/// kept (a circle came, went, or changed its radius, mass or restitution). `known` holds how
/// many circles the engine has and each one's index by entity.
fn moved_since(
    engine: &EventEngine,
    known: (usize, &EntityHashMap<usize>),
    changed: &[Entity],
    circles: &SolverCircles,
    restitution_of: impl Fn(Option<&Restitution>) -> f64,
) -> Result<Vec<(usize, DVec2, DVec2)>, &'static str> {
    let (count, index) = known;
    if circles.iter().len() != count {
        return Err("circles were spawned or despawned");
    }
    let mut moved = Vec::new();
    for &entity in changed {
        let (Some(&i), Ok((_, p, v, r, m, e, ..))) = (index.get(&entity), circles.get(entity))
        else {
            return Err("circles were spawned or despawned");
        };
        if engine.body(i) != (r.0, m.inverse(), restitution_of(e)) {
            return Err("a radius, mass or restitution changed");
        }
        if (p.0, v.0) != (engine.position(i), engine.velocity(i)) {
            moved.push((i, p.0, v.0));
        }
    }
    Ok(moved)
}

/// Processes the step's events (within the solver's budget), counts what they did and, when
/// recording, writes their hits as messages.
fn advance_engine(
    (solver, dt, stop): (Solver, f64, Option<&StopRequest>),
    state: &mut EngineState,
    counted: (&mut PairCollisions, &mut WallCollisions),
    mut messages: (MessageWriter<CircleHit>, MessageWriter<WallHit>),
) {
    let Some(engine) = state.engine.as_mut() else {
        return;
    };
    let per_circle = match solver {
        Solver::Swept => SWEPT_EVENTS_PER_CIRCLE,
        _ => EXACT_EVENTS_PER_CIRCLE,
    };
    let budget = per_circle * (engine.len() as u64 + 1);
    let t_start = engine.now();
    let t_end = t_start + dt;
    let stop = || stop.is_some_and(StopRequest::raised);
    if engine.advance_until_stopped(t_end, budget, stop).is_err() {
        engine.drift_to(t_end);
        state.budget_exhausted += 1;
    }
    if let Some(log) = engine.drain_hits() {
        let entity = |i: u32| state.entities[i as usize];
        log.send_circle_hits(entity, -t_start, &mut messages.0);
        log.send_wall_hits(entity, -t_start, &mut messages.1);
    }
    let (pairs, walls) = counted;
    let stats = engine.stats();
    let last = std::mem::replace(&mut state.last_stats, stats);
    pairs.count += stats.pair_collisions - last.pair_collisions;
    pairs.virial += stats.virial - last.virial;
    pairs.immovable_work += stats.immovable_work - last.immovable_work;
    pairs.immovable_impulse += stats.immovable_impulse - last.immovable_impulse;
    walls.count += stats.wall_collisions - last.wall_collisions;
    walls.impulse += stats.wall_impulse - last.wall_impulse;
}

/// Writes the engine's positions and velocities back to the circles that changed. Circles found
/// in another order than the engine's (an entity moved between archetypes) are written by
/// entity, and the next step rebuilds.
fn write_back(state: &mut EngineState, circles: &mut SolverCircles) {
    let Some(engine) = state.engine.as_ref() else {
        return;
    };
    for (i, (entity, mut p, mut v, ..)) in circles.iter_mut().enumerate() {
        if state.entities.get(i) != Some(&entity) {
            state.reordered = true;
            break;
        }
        let (position, velocity) = (engine.position(i), engine.velocity(i));
        if p.0 != position {
            p.0 = position;
        }
        if v.0 != velocity {
            v.0 = velocity;
        }
    }
    if state.reordered {
        for (i, &entity) in state.entities.iter().enumerate() {
            if let Ok((_, mut p, mut v, ..)) = circles.get_mut(entity) {
                (p.0, v.0) = (engine.position(i), engine.velocity(i));
            }
        }
    }
}
