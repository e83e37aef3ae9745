//! When things run: the public [`CircleSystems`] sets, the [`CircleStep`] schedule that one
//! substep of the discrete solvers runs, the registry in which each solver's plugin registers
//! the schedule that advances it ([`register_solver`]), the [`StepTotals`] they advance, and
//! [`StepPlugin`], the core plugin every other plugin builds on.
//!
//! Data flow per fixed step (in `FixedUpdate`): `CircleSystems::Step` orders the circles
//! ([`CircleOrder`]) and runs the current solver's schedule as many times as it has substeps,
//! with `dt / substeps`: [`CircleStep`] (`Forces` → `Integrate` → `Boundary` → `Collide`) under
//! `discrete` and `substeps=N`, the event engine's schedule once under `swept` and `exact`, the
//! contact solver's once under `soft` (which substeps inside); then `CircleSystems::Diagnostics`
//! measures the result. Before the step, `CircleSystems::Sleep` puts circles at rest to sleep
//! and wakes the ones that were hit or moved. Spawning happens outside the fixed clock
//! (`Startup` and `PreUpdate`, set `CircleSystems::Spawn`) so a paused simulation can still be
//! reset.

use std::time::Duration;

use bevy::ecs::schedule::{
    InternedScheduleLabel, InternedSystemSet, IntoScheduleConfigs, ScheduleLabel,
    SingleThreadedExecutor,
};
use bevy::ecs::system::SystemState;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::config::{Effects, SoftConfig, Solver};
use crate::base::order::{CircleOrder, SerialCircles};
use crate::base::segment::Segments;
use crate::step::effects::reconcile_effects;

/// The system sets of the simulation, in the order they run.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CircleSystems {
    /// Placing circles (`Startup`, and `PreUpdate` for respawn requests).
    Spawn,
    /// Putting circles at rest to sleep and waking the ones hit or moved from outside, before
    /// the step (`FixedUpdate`).
    Sleep,
    /// Advancing one fixed step: runs [`CircleStep`] (`FixedUpdate`).
    Step,
    /// Forces that change velocity: gravity, drag, yours (inside every solver's schedule,
    /// before the solver's own sets).
    Forces,
    /// Moving circles over the step's `dt` (inside [`CircleStep`]).
    Integrate,
    /// Keeping circles inside the arena (inside [`CircleStep`]).
    Boundary,
    /// Resolving circle-circle contacts (inside [`CircleStep`]).
    Collide,
    /// Finding what overlaps each sensor after the step (`FixedUpdate`).
    Sensors,
    /// Measuring energy, momentum and collision rates after the step (`FixedUpdate`).
    Diagnostics,
}

/// The schedule of one solver substep. Run by `run_circle_step` once per substep.
#[derive(ScheduleLabel, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CircleStep;

/// How one solver advances a fixed step, as its plugin registers it with [`register_solver`].
#[derive(Clone, Copy, Debug)]
pub struct SolverStep {
    /// Whether this is the step of `solver`.
    pub advances: fn(Solver) -> bool,
    /// The schedule one run covers.
    pub schedule: InternedScheduleLabel,
    /// How many runs of `schedule` make a fixed step under `solver`, each over `dt / runs`.
    pub runs: fn(Solver) -> u32,
}

/// The solvers' steps, one per solver plugin present.
#[derive(Resource, Default, Debug)]
pub struct SolverSteps(Vec<SolverStep>);

impl SolverSteps {
    /// The step that advances `solver`, if its plugin is present.
    pub fn of(&self, solver: Solver) -> Option<SolverStep> {
        self.0.iter().copied().find(|step| (step.advances)(solver))
    }
}

/// Registers `step` as the way to advance the solvers it names, and makes its schedule: run
/// by one thread (a step's systems run in a chain, so more threads would only add wake-ups to
/// every substep), with [`CircleSystems::Forces`] first and then `own`, the solver's sets.
pub fn register_solver(
    app: &mut App,
    step: SolverStep,
    own: impl IntoScheduleConfigs<InternedSystemSet, ()>,
) {
    app.init_schedule(step.schedule)
        .edit_schedule(step.schedule, |s| {
            s.set_executor(SingleThreadedExecutor::new());
        })
        .configure_sets(step.schedule, own.after(CircleSystems::Forces));
    app.world_mut()
        .get_resource_or_init::<SolverSteps>()
        .0
        .push(step);
}

/// The simulated time one run of [`CircleStep`] covers, in seconds (`dt / substeps`).
#[derive(Resource, Clone, Copy, Debug, PartialEq, Default)]
pub struct StepDt(pub f64);

/// Seconds from the start of the fixed step to the start of the running (sub)step: what a hit
/// found in a substep adds to its time.
#[derive(Resource, Clone, Copy, Debug, PartialEq, Default)]
pub struct SubstepStart(pub f64);

/// Fixed steps advanced and the simulated time they covered, since the last (re)spawn.
#[derive(
    Resource, Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize,
)]
pub struct StepTotals {
    /// Fixed steps advanced.
    pub steps: u64,
    /// Simulated seconds advanced.
    pub sim_seconds: f64,
}

impl StepTotals {
    /// What was advanced between `earlier` and these totals (all zero across a respawn, which
    /// restarts the totals).
    pub fn since(&self, earlier: &StepTotals) -> StepTotals {
        if self.steps < earlier.steps {
            return StepTotals::default();
        }
        StepTotals {
            steps: self.steps - earlier.steps,
            sim_seconds: self.sim_seconds - earlier.sim_seconds,
        }
    }
}

/// A request from outside the app (the command line's signal handler) to end the current step
/// as soon as it can: the event engine, which can spend seconds in one step, then ends it as
/// when its event budget runs out (everything drifts to the step's end, counted in
/// `budget_exhausted`, and the engine is not kept); a build of the engine it stops moves
/// nothing that step (also counted); a placement of circles it stops places no random circles,
/// and a spawning it stops spawns no more batches ([`SpawnReport::interrupted`]).
/// Absent, or never set, nothing changes.
///
/// [`SpawnReport::interrupted`]: crate::game::spawn::SpawnReport::interrupted
#[derive(Resource, Clone, Debug, Default)]
pub struct StopRequest(pub std::sync::Arc<std::sync::atomic::AtomicBool>);

impl StopRequest {
    /// Whether a stop was asked for.
    pub fn raised(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// The core plugin: inserts the arena, segment walls, solver and effect parameters, sets the
/// fixed clock, orders the [`CircleSystems`] sets of `FixedUpdate` and runs the solver's step
/// in them. The other plugins add systems to those sets and register the solvers. Before
/// each fixed step (`FixedFirst`) it reconciles the effects' systems with the [`Effects`],
/// [`Arena`] and [`Segments`] if any of them changed, however they were changed.
#[derive(Clone, Debug)]
pub struct StepPlugin {
    /// The arena the circles live in.
    pub arena: Arena,
    /// How a fixed step is advanced.
    pub solver: Solver,
    /// The effects and their parameters (which ones get systems is up to the effect plugins).
    pub effects: Effects,
    /// The fixed step in seconds.
    pub dt: f64,
    /// The segment walls inside the arena.
    pub segments: Segments,
    /// How the `soft` solver's contacts behave.
    pub soft: SoftConfig,
}

impl Default for StepPlugin {
    fn default() -> Self {
        Self {
            arena: Arena::default(),
            solver: Solver::default(),
            effects: Effects::default(),
            dt: 1.0 / 60.0,
            segments: Segments::default(),
            soft: SoftConfig::default(),
        }
    }
}

impl Plugin for StepPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<Arena>()
            .register_type::<Solver>()
            .insert_resource(self.arena)
            .register_type::<Effects>()
            .insert_resource(self.solver)
            .insert_resource(self.effects)
            .register_type::<Segments>()
            .insert_resource(self.segments.clone())
            .register_type::<SoftConfig>()
            .insert_resource(self.soft)
            .insert_resource(Time::<Fixed>::from_duration(Duration::from_secs_f64(
                self.dt,
            )))
            .init_resource::<StepDt>()
            .init_resource::<SubstepStart>()
            .init_resource::<StepTotals>()
            .init_resource::<CircleOrder>()
            .init_resource::<SolverSteps>()
            .configure_sets(
                FixedUpdate,
                (
                    CircleSystems::Sleep,
                    CircleSystems::Step,
                    CircleSystems::Sensors,
                    CircleSystems::Diagnostics,
                )
                    .chain(),
            )
            .add_systems(Startup, allow_long_steps)
            // Whoever changed the effects, the arena or the segment walls (a game system, a
            // reloaded scene, the panel), the next step runs the systems they call for.
            .add_systems(
                FixedFirst,
                reconcile_effects.run_if(
                    resource_changed::<Effects>
                        .or_eager(resource_changed::<Arena>)
                        .or_eager(resource_changed::<Segments>),
                ),
            )
            .add_systems(FixedUpdate, run_circle_step.in_set(CircleSystems::Step));
    }
}

/// Lets virtual time advance by at least one fixed step per frame: Bevy caps a frame's virtual
/// delta (250 ms by default), which would otherwise stop a scene with a longer `dt` (a 1 s
/// step) from ever stepping.
pub(crate) fn allow_long_steps(fixed: Res<Time<Fixed>>, mut virt: ResMut<Time<Virtual>>) {
    let step = fixed.timestep();
    if virt.max_delta() < step {
        virt.set_max_delta(step);
    }
}

/// Advances one fixed step with the current [`Solver`]: orders the circles by serial
/// ([`CircleOrder`]), then runs the schedule its plugin registered as many times as it says,
/// each over its share of `dt`. Without the solver's plugin nothing moves (said once).
pub(crate) fn run_circle_step(
    world: &mut World,
    (circles, mut warned): (
        &mut SystemState<SerialCircles<'static, 'static>>,
        Local<bool>,
    ),
) {
    let mut order = std::mem::take(&mut *world.resource_mut::<CircleOrder>());
    let circles = circles.get(world).expect("a query is always valid");
    order.update(circles.iter().map(|(e, &serial)| (e, serial)));
    *world.resource_mut::<CircleOrder>() = order;
    let solver = *world.resource::<Solver>();
    let dt = world.resource::<Time<Fixed>>().timestep().as_secs_f64();
    match world.resource::<SolverSteps>().of(solver) {
        Some(step) => {
            let runs = (step.runs)(solver).max(1);
            let sub_dt = dt / f64::from(runs);
            world.resource_mut::<StepDt>().0 = sub_dt;
            for k in 0..runs {
                world.resource_mut::<SubstepStart>().0 = f64::from(k) * sub_dt;
                world.run_schedule(step.schedule);
            }
        }
        None if !*warned => {
            *warned = true;
            warn!("no plugin advances the {solver} solver: the circles stay where they are");
        }
        None => {}
    }
    let mut totals = world.resource_mut::<StepTotals>();
    totals.steps += 1;
    totals.sim_seconds += dt;
}

/// The schedules the simulation adds systems to, in the order a frame meets them.
pub const SIMULATION_SCHEDULES: [&str; 6] = [
    "Startup",
    "PreUpdate",
    "FixedUpdate",
    "CircleStep",
    "ContinuousStep",
    "SoftStep",
];

/// The simulation's systems, as `(schedule, system)` names in execution order, for every
/// schedule in [`SIMULATION_SCHEDULES`]. Only this crate's systems are listed. Initializes the
/// schedules it looks at (harmless: Bevy would on first run).
pub fn scheduled_systems(app: &mut App) -> Vec<(String, String)> {
    let world = app.world_mut();
    let labels: Vec<_> = world
        .resource::<Schedules>()
        .iter()
        .map(|(_, schedule)| schedule.label())
        .filter(|label| SIMULATION_SCHEDULES.contains(&format!("{label:?}").as_str()))
        .collect();
    let mut listed = Vec::new();
    for name in SIMULATION_SCHEDULES {
        let Some(&label) = labels.iter().find(|l| format!("{l:?}") == name) else {
            continue;
        };
        world.schedule_scope(label, |world, schedule| {
            if let Err(e) = schedule.initialize(world) {
                panic!("schedule {name} does not build: {e}");
            }
            let systems = schedule.systems().expect("initialized above");
            for (_, system) in systems {
                let system_name = system.name().to_string();
                if system_name.starts_with(concat!(env!("CARGO_CRATE_NAME"), "::")) {
                    listed.push((name.to_owned(), system_name));
                }
            }
        });
    }
    listed
}
