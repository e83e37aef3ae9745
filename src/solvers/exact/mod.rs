//! The continuous solvers, `swept` and `exact`, built on one event-driven `engine`:
//! - `exact` keeps one engine alive across steps (cost per collision, not per step) and only
//!   rebuilds it when something outside changed the circles (a respawn, a drag with the mouse,
//!   a force effect, a solver switch);
//! - `swept` builds a fresh engine from the current state every step and resolves that step's
//!   hits in time order, with a bounded number of events per step ([`EventBudget`]);
//!   past the bound the rest of the step is free flight and the missed hits resolve next step.
//!   A pile asleep under gravity, where nothing moves and nothing outside touched a circle,
//!   keeps its engine, and a step of it writes back what a fresh engine would.
//!
//! Both handle walls, periodic edges and collisions themselves (trading spin when the effects
//! make hits rough, `engine::Roughness`), so they run in the
//! [`ContinuousStep`] schedule after the force effects, as one system in three parts: gather the
//! circles into the engine (rebuilding it if needed), advance it by the step, write the circles
//! back. One system, so that its change filters see only what others wrote since its last
//! write-back: a step where nothing outside touched the circles pays for its events, Bevy's
//! change-tick check and one write per circle, not for comparing every circle's values.

pub(crate) mod engine;
mod keep;
mod outside;
pub(crate) mod pack;

use bevy::ecs::schedule::ScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{CircleFilters, CollisionLayers, Sensor};
use crate::base::components::{Inertia, Radius, Restitution, Sleep, SolverCircles, SpinCircles};
use crate::base::config::{Effects, Solver};
use crate::base::hits::PairCollisions;
use crate::base::hits::{CircleHit, WallHit};
use crate::base::order::CircleOrder;
use crate::base::segment::Segments;
use crate::step::bodies::write_motion;
use crate::step::boundary::WallCollisions;
use crate::step::effects::{Effect, register_effect};
use crate::step::forces::drag_systems;
use crate::step::integrate::turn_circles;
use crate::step::schedule::{SolverStep, StepDt, StopRequest, register_solver};
use crate::step::sleep::Sleeping;
use keep::{EngineViews, Own, gather_into_engine};

pub use keep::EngineState;

/// Events a `swept` step may process per circle before the rest of the step is free flight
/// (the default of [`EventBudget::swept`]).
pub const SWEPT_EVENTS_PER_CIRCLE: u64 = 64;
/// The same bound for `exact`, high enough to be reached only by inelastic collapse or speeds
/// that cross the arena millions of times a step (the default of [`EventBudget::exact`]).
pub const EXACT_EVENTS_PER_CIRCLE: u64 = 100_000;

/// Events per circle a `swept` step may process, at least, per fall of the least radius
/// (`√(r/g)`, [`EventEngine::falls_in`](engine::EventEngine::falls_in)): under strong gravity
/// its circles bounce about that often, and its own bound ([`SWEPT_EVENTS_PER_CIRCLE`]) would
/// cut the step short (`exact`'s is far above what any gravity a scene may have needs).
pub const GRAVITY_EVENTS_PER_FALL: f64 = 8.0;

/// How many events a `swept` or `exact` step may process, per circle (and one circle more;
/// under strong gravity more for `swept`, [`GRAVITY_EVENTS_PER_FALL`]), before the rest of the
/// step is free flight (counted in
/// [`EngineState::budget_exhausted`]). A game that must bound the work of a frame lowers
/// `exact`'s; the collisions it skips then show as overlapping, approaching pairs, resolved
/// next step.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Eq)]
#[reflect(Resource, Debug)]
pub struct EventBudget {
    /// Events per circle and step under `swept`.
    pub swept: u64,
    /// Events per circle and step under `exact`.
    pub exact: u64,
}

impl Default for EventBudget {
    fn default() -> Self {
        Self {
            swept: SWEPT_EVENTS_PER_CIRCLE,
            exact: EXACT_EVENTS_PER_CIRCLE,
        }
    }
}

impl EventBudget {
    /// The events a step of `solver` may process with `circles` circles, the least of which
    /// falls its radius `falls` times in the step ([`GRAVITY_EVENTS_PER_FALL`]).
    pub fn for_step(&self, solver: Solver, circles: usize, falls: f64) -> u64 {
        let per_circle = match solver {
            Solver::Swept => self
                .swept
                .max((GRAVITY_EVENTS_PER_FALL * falls).ceil() as u64),
            _ => self.exact,
        };
        per_circle.saturating_mul(circles as u64 + 1)
    }
}

/// The schedule of one step of `swept` and `exact`: drag and your forces in
/// [`CircleSystems::Forces`](crate::step::schedule::CircleSystems::Forces), then [`ContinuousSystems`], which handles motion, walls and
/// collisions together.
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ContinuousStep;

/// The continuous step itself, in [`ContinuousStep`] after the forces.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ContinuousSystems;

/// The `swept` and `exact` solvers: their step in [`ContinuousStep`], run once a fixed step.
#[derive(Clone, Copy, Debug, Default)]
pub struct ContinuousPlugin;

impl Plugin for ContinuousPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<EngineState>()
            .init_resource::<EventBudget>()
            .register_type::<EventBudget>()
            .init_resource::<Segments>()
            .init_resource::<PairCollisions>()
            .init_resource::<WallCollisions>()
            .add_message::<CircleHit>()
            .add_message::<WallHit>();
        let step = SolverStep {
            advances: Solver::is_continuous,
            schedule: ContinuousStep.intern(),
            runs: |_| 1,
        };
        register_solver(app, step, ContinuousSystems);
        // The engine flies circles under gravity itself; drag it takes from outside.
        register_effect(app, Effect::Drag, &[ContinuousStep.intern()], drag_systems);
        app.add_systems(ContinuousStep, continuous_step.in_set(ContinuousSystems));
    }
}

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
    budget: Res<'w, EventBudget>,
    stop: Option<Res<'w, StopRequest>>,
    order: Res<'w, CircleOrder>,
}

/// The circles whose layers were set or changed, or that became sensors, since the last step:
/// a query of its own, which matches nothing (and costs nothing) in a scene without layers.
type Relayered = (
    With<Radius>,
    Or<(Changed<CollisionLayers>, Changed<Sensor>)>,
);

/// The components a circle may lose that a kept engine cannot tell it lost.
#[derive(SystemParam)]
struct Lost<'w, 's> {
    restitution: RemovedComponents<'w, 's, Restitution>,
    inertia: RemovedComponents<'w, 's, Inertia>,
    layers: RemovedComponents<'w, 's, CollisionLayers>,
    sensor: RemovedComponents<'w, 's, Sensor>,
}

impl Lost<'_, '_> {
    /// Whether any circle still `alive` lost its own restitution, moment of inertia, layers or
    /// sensor since the last look (and forgets it). A despawned circle's losses are not: that
    /// circles went is what the step sees from their count (and a rollback library despawns
    /// circles to spawn them again with all their parts).
    fn any(&mut self, alive: impl Fn(Entity) -> bool) -> bool {
        let mut lost = false;
        for entity in self.restitution.read() {
            lost |= alive(entity);
        }
        for entity in self.inertia.read() {
            lost |= alive(entity);
        }
        for entity in self.layers.read() {
            lost |= alive(entity);
        }
        for entity in self.sensor.read() {
            lost |= alive(entity);
        }
        lost
    }
}

/// The `swept` / `exact` step: gathers the circles into the engine, advances it by the step and
/// writes the circles back (see the module docs for why this is one system).
fn continuous_step(
    setup: StepSetup,
    mut state: ResMut<EngineState>,
    own: (Query<(), With<Restitution>>, CircleFilters),
    (mut lost, relayered): (Lost, Query<(), Relayered>),
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
        budget,
        stop,
        order,
    } = setup;
    let (own_restitution, filters) = own;
    let slept = !circles.p5().is_empty();
    let lost = {
        let all = circles.p0();
        lost.any(|e| all.contains(e))
    };
    let own = Own {
        lost: lost || !relayered.is_empty(),
        restitution: !own_restitution.is_empty(),
        filters: &filters,
        slept,
    };
    gather_into_engine(
        (
            (*solver, *arena, *effects, &segments),
            &order,
            stop.as_deref(),
        ),
        &mut state,
        own,
        &mut circles,
    );
    let Some(engine) = state.engine.as_ref() else {
        // A stop gave up the build: this step moves, turns and wakes nothing.
        return;
    };
    // Nothing moves (a pile asleep): no event can come, and the engine, kept or fresh, is not
    // advanced; the step writes back what a fresh engine advanced by it would.
    let still = *solver == Solver::Swept && effects.gravity.is_some() && engine.is_still();
    if !still {
        advance_engine(
            (*solver, dt.0, *budget, stop.as_deref()),
            &mut state,
            (&mut counted.pairs, &mut counted.walls),
            messages,
        );
    }
    write_back(&state, &order, &mut circles.p0());
    counted.sleeping.count = match still {
        true => age_rest(&state, &mut circles.p2(), dt.0),
        false => write_back_sleep(&state, &mut circles.p2(), counted.sleeping.count),
    };
    if !write_back_turning(&state, &mut circles.p3()) {
        turn_circles(&mut circles.p3(), dt.0); // smooth circles trade no spin
    }
}

/// Writes each circle's spin and angle back from a rough engine, which turns them itself, and
/// says whether it did (a smooth engine leaves them to turn at their own rate).
fn write_back_turning(state: &EngineState, spins: &mut SpinCircles) -> bool {
    let Some(engine) = state.engine.as_ref().filter(|e| !e.roughness().is_smooth()) else {
        return false;
    };
    for (i, &entity) in state.entities.iter().enumerate() {
        let (Some((spin, angle)), Ok((w, r, ..))) = (engine.turn(i), spins.get_mut(entity)) else {
            continue;
        };
        if let Some(mut w) = w
            && w.0 != spin
        {
            w.0 = spin;
        }
        if let Some(mut r) = r
            && r.0 != angle
        {
            r.0 = angle;
        }
    }
    true
}

/// Writes each circle's rest back to its [`Sleep`] (in the engine's order), for the next engine
/// `swept` builds and for checkpoints, and returns how many circles sleep. Only under gravity:
/// without it nothing rests, and circles still marked asleep (`asleep_before` of them, from a
/// checkpoint) fly like the others, so they are marked awake.
fn write_back_sleep(
    state: &EngineState,
    sleep: &mut Query<&mut Sleep>,
    asleep_before: usize,
) -> usize {
    let Some(engine) = state.engine.as_ref() else {
        return 0;
    };
    let falling = matches!(state.setup, Some((_, effects, _)) if effects.gravity.is_some());
    if !falling {
        if asleep_before > 0 {
            for mut s in sleep.iter_mut().filter(|s| s.asleep) {
                *s = Sleep::default();
            }
        }
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

/// What a fresh engine built from the circles as they are, in which nothing moves, writes back
/// to their [`Sleep`] after a step of `dt` (so a kept one need not be advanced): each circle's
/// time near its anchor grows by the step, worked out as that engine's [`Rest`] of it would be
/// (`now - since` with `now = dt`, `since = -slow_for`), the rest stays. Returns how many sleep.
///
/// [`Rest`]: engine::Rest
fn age_rest(state: &EngineState, sleep: &mut Query<&mut Sleep>, dt: f64) -> usize {
    let mut asleep = 0;
    for &entity in &state.entities {
        if let Ok(mut s) = sleep.get_mut(entity) {
            asleep += usize::from(s.asleep);
            let slow_for = (dt - (-s.slow_for)).max(0.0);
            if s.slow_for != slow_for {
                s.slow_for = slow_for;
            }
        }
    }
    asleep
}

/// Processes the step's events (within the solver's budget), counts what they did and, when
/// recording, writes their hits as messages.
fn advance_engine(
    (solver, dt, budget, stop): (Solver, f64, EventBudget, Option<&StopRequest>),
    state: &mut EngineState,
    counted: (&mut PairCollisions, &mut WallCollisions),
    mut messages: (MessageWriter<CircleHit>, MessageWriter<WallHit>),
) {
    let Some(engine) = state.engine.as_mut() else {
        return;
    };
    // Only `swept`'s bound grows with gravity: `exact` need not look for its least radius.
    let falls = match solver {
        Solver::Swept => engine.falls_in(dt),
        _ => 0.0,
    };
    let budget = budget.for_step(solver, engine.len(), falls);

    let t_start = engine.now();
    let t_end = t_start + dt;
    let stop = || stop.is_some_and(StopRequest::raised);
    if engine.advance_until_stopped(t_end, budget, stop).is_err() {
        if stop() {
            // The run ends after this step: its engine is read back, not kept.
            engine.fly_unpredicted_to(t_end);
            state.stopped = true;
        } else {
            engine.drift_to(t_end);
        }
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

/// Writes the engine's positions and velocities back to the circles that changed, in serial
/// order (by entity if the circles are no longer the engine's: spawned or despawned in the
/// step, and the next step rebuilds).
fn write_back(state: &EngineState, order: &CircleOrder, circles: &mut SolverCircles) {
    let Some(engine) = state.engine.as_ref() else {
        return;
    };
    let entities = (order.entities() != state.entities).then_some(&state.entities[..]);
    write_motion(order, entities, circles, |i| {
        (engine.position(i), engine.velocity(i))
    });
}
