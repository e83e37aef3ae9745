//! The continuous solvers, `swept` and `exact`, built on one event-driven [`engine`]:
//! - `exact` keeps one engine alive across steps (cost per collision, not per step) and only
//!   rebuilds it when something outside changed the circles (a respawn, a drag with the mouse,
//!   a force effect, a solver switch);
//! - `swept` builds a fresh engine from the current state every step and resolves that step's
//!   hits in time order, with a bounded number of events per step ([`SWEPT_EVENTS_PER_CIRCLE`]);
//!   past the bound the rest of the step is free flight and the missed hits resolve next step.
//!
//! Both handle walls, periodic edges and collisions themselves, so they run in the
//! [`ContinuousStep`] schedule after the force effects, as three systems: gather the circles
//! into the engine (rebuilding it if needed), advance it by the step, write the circles back.

pub mod engine;
pub mod pack;
pub mod queue;
pub mod toi;

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::arena::Arena;
use crate::boundary::WallCollisions;
use crate::circle::CircleState;
use crate::collide::PairCollisions;
use crate::components::{Restitution, SolverCircles};
use crate::config::{Effects, Solver};
use crate::hits::{CircleHit, WallHit};
use crate::schedule::{CircleSystems, ContinuousStep, StepDt};
use crate::segment::Segments;
use engine::{EngineSnapshot, EventEngine, EventStats};

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
                (gather_into_engine, advance_engine, write_back)
                    .chain()
                    .in_set(CircleSystems::Continuous),
            );
    }
}

/// The engine kept between `exact` steps, with what it last wrote to the ECS, so a change made
/// by anything else can be detected.
#[derive(Resource, Default)]
pub struct EngineState {
    engine: Option<EventEngine>,
    entities: Vec<Entity>,
    written: Vec<(DVec2, DVec2)>,
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
            effects.restitution,
            effects.wall_restitution,
        )?;
        engine.record_hits(effects.hit_messages);
        if let Some(i) = (0..engine.len()).find(|&i| engine.position(i) != states[i].position) {
            return Err(format!(
                "engine state of circle {i} puts it elsewhere than the circle"
            ));
        }
        self.last_stats = engine.stats();
        self.engine = Some(engine);
        self.entities = circles.iter().map(|&(e, _)| e).collect();
        self.written = states.iter().map(|c| (c.position, c.velocity)).collect();
        self.setup = Some((arena, effects, Solver::Exact));
        self.segments = segments.clone();
        Ok(())
    }
}

/// Keeps the `exact` engine if nothing but the engine itself changed the circles since the last
/// step; updates it if user code moved or steered a few of them (a teleport, a kinematic
/// paddle); otherwise (and always for `swept`) builds a fresh one from the circles. Says which
/// in a debug log.
fn gather_into_engine(
    solver: Res<Solver>,
    arena: Res<Arena>,
    effects: Res<Effects>,
    segments: Res<Segments>,
    mut state: ResMut<EngineState>,
    own_restitution: Query<(), With<Restitution>>,
    circles: SolverCircles,
) {
    let state = &mut *state;
    let setup = (*arena, *effects, *solver);
    let restitution_of = |own: Option<&Restitution>| own.map_or(effects.restitution, |e| e.0);
    let reason = match (&mut state.engine, *solver) {
        (Some(engine), Solver::Exact)
            if state.setup == Some(setup) && state.segments == *segments =>
        {
            let known = (state.entities.as_slice(), state.written.as_slice());
            match moved_since(engine, known, &circles, restitution_of) {
                Ok(moved) if moved.is_empty() => return,
                Ok(moved) if moved.len() <= circles.iter().len() / MOVED_FOR_REBUILD => {
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
    if *solver == Solver::Exact {
        debug!("exact engine: rebuilt ({reason})");
    }
    let bodies: Vec<CircleState> = circles
        .iter()
        .map(|(_, p, v, r, m, _)| CircleState::new(p.0, v.0, r.0).with_mass(m.0))
        .collect();
    let mut engine = EventEngine::new(
        &bodies,
        &arena,
        &segments.0,
        effects.restitution,
        effects.wall_restitution,
    );
    if !own_restitution.is_empty() {
        engine.set_own_restitutions(circles.iter().map(|c| restitution_of(c.5)).collect());
    }
    engine.record_hits(effects.hit_messages);
    state.last_stats = engine.stats();
    state.engine = Some(engine);
    state.entities = circles.iter().map(|(e, ..)| e).collect();
    state.setup = Some(setup);
    if state.segments != *segments {
        state.segments = segments.clone();
    }
    state.rebuilds += 1;
}

/// The circles user code moved or steered since the kept `engine` last wrote them (index, new
/// position and velocity), in one pass over `circles` against the `known` entities and what was
/// written to them; or why the engine cannot be kept (a circle came, went, or changed its
/// radius, mass or restitution).
fn moved_since(
    engine: &EventEngine,
    known: (&[Entity], &[(DVec2, DVec2)]),
    circles: &SolverCircles,
    restitution_of: impl Fn(Option<&Restitution>) -> f64,
) -> Result<Vec<(usize, DVec2, DVec2)>, &'static str> {
    let (entities, written) = known;
    if circles.iter().len() != entities.len() {
        return Err("circles were spawned or despawned");
    }
    let mut moved = Vec::new();
    for (i, (c, (&entity, &was))) in circles.iter().zip(entities.iter().zip(written)).enumerate() {
        if c.0 != entity {
            return Err("circles were spawned or despawned");
        }
        if engine.body(i) != (c.3.0, c.4.inverse(), restitution_of(c.5)) {
            return Err("a radius, mass or restitution changed");
        }
        if (c.1.0, c.2.0) != was {
            moved.push((i, c.1.0, c.2.0));
        }
    }
    Ok(moved)
}

/// Processes the step's events (within the solver's budget), counts what they did and, when
/// recording, writes their hits as messages.
fn advance_engine(
    solver: Res<Solver>,
    dt: Res<StepDt>,
    mut state: ResMut<EngineState>,
    mut counted: (ResMut<PairCollisions>, ResMut<WallCollisions>),
    mut messages: (MessageWriter<CircleHit>, MessageWriter<WallHit>),
) {
    let state = &mut *state;
    let Some(engine) = state.engine.as_mut() else {
        return;
    };
    let per_circle = match *solver {
        Solver::Swept => SWEPT_EVENTS_PER_CIRCLE,
        _ => EXACT_EVENTS_PER_CIRCLE,
    };
    let budget = per_circle * (engine.len() as u64 + 1);
    let t_start = engine.now();
    let t_end = t_start + dt.0;
    if engine.advance_to(t_end, budget).is_err() {
        engine.drift_to(t_end);
        state.budget_exhausted += 1;
    }
    if let Some(log) = engine.drain_hits() {
        let entity = |i: u32| state.entities[i as usize];
        log.send_circle_hits(entity, -t_start, &mut messages.0);
        log.send_wall_hits(entity, -t_start, &mut messages.1);
    }
    let (pairs, walls) = &mut counted;
    let stats = engine.stats();
    let last = std::mem::replace(&mut state.last_stats, stats);
    pairs.count += stats.pair_collisions - last.pair_collisions;
    pairs.virial += stats.virial - last.virial;
    pairs.immovable_work += stats.immovable_work - last.immovable_work;
    pairs.immovable_impulse += stats.immovable_impulse - last.immovable_impulse;
    walls.count += stats.wall_collisions - last.wall_collisions;
    walls.impulse += stats.wall_impulse - last.wall_impulse;
}

/// Writes the engine's positions and velocities back to the circles that changed, and
/// remembers what it wrote.
fn write_back(mut state: ResMut<EngineState>, mut circles: SolverCircles) {
    let state = &mut *state;
    let Some(engine) = state.engine.as_ref() else {
        return;
    };
    state.written.clear();
    for (i, (_, mut p, mut v, ..)) in circles.iter_mut().enumerate() {
        let (position, velocity) = (engine.position(i), engine.velocity(i));
        if p.0 != position {
            p.0 = position;
        }
        if v.0 != velocity {
            v.0 = velocity;
        }
        state.written.push((position, velocity));
    }
}
