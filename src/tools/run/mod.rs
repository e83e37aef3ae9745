//! Headless runs: [`headless_app`], a `MinimalPlugins` app in which every `update()` is exactly
//! one fixed step; [`run_steps`], the one loop that steps such an app, times the stepping alone
//! and measures the state as it goes (the `run` command, the accuracy study and the hard-case
//! tests all use it); and [`Report`], what a run did — the JSON `moving_circles run --report`
//! writes, whose fields are a contract other tools rely on.

use std::time::{Duration, Instant};

use bevy::ecs::schedule::SingleThreadedExecutor;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::circle::{CircleState, Parts, from_components, inertia, snapshot};
use crate::base::collision_layers::{LayeredDisc, layered_disc};
use crate::base::components::{Inertia, Sleep};
use crate::base::config::{CirclesConfig, Effects, Solver};
use crate::base::error::FieldError;
use crate::base::hits::PairCollisions;
use crate::collision::overlaps::Overlaps;
use crate::game::diagnostics::{Measuring, Pressure, Totals, dropped_totals, relative_change};
use crate::game::plugins::CirclesPlugins;
use crate::game::spawn::{Dropped, SpawnReport};
use crate::solvers::exact::EngineState;
use crate::step::boundary::WallCollisions;
use crate::step::effects::{Effect, EffectRegistry};
use crate::step::schedule::StepTotals;
use crate::tools::scene::check::check_motion;

/// A headless app for `config`, past `Startup` (circles spawned), in which every `update()`
/// advances exactly one fixed step.
///
/// Every schedule runs on the single-threaded executor: a headless step is a chain of systems
/// with nothing to overlap, and the multi-threaded executor's thread wake-ups in each of the
/// dozen schedules of an `update()` cost more than the stepping of 10 000 circles without
/// collisions. Kernels that do parallelise (the pair scan) still use the task pools.
///
/// ```
/// use moving_circles::prelude::*;
/// use moving_circles::tools::run::headless_app;
///
/// let mut app = headless_app(CirclesConfig::default());
/// app.update();
/// assert_eq!(app.world().resource::<StepTotals>().steps, 1);
/// ```
pub fn headless_app(config: CirclesConfig) -> App {
    headless_app_with(config, |_| {})
}

/// [`headless_app`] with more added by `setup` before the app is finished: your own plugins,
/// or the app's input and HUD plugins in a test.
pub fn headless_app_with(config: CirclesConfig, setup: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, CirclesPlugins::new(config)))
        .insert_resource(TimeUpdateStrategy::FixedTimesteps(1));
    setup(&mut app);
    app.finish();
    app.cleanup();
    for (_, schedule) in app.world_mut().resource_mut::<Schedules>().iter_mut() {
        schedule.set_executor(SingleThreadedExecutor::new());
    }
    app.update();
    app
}

/// One look at the state after a step of [`run_steps`].
pub struct Sample<'a> {
    /// Steps done so far.
    pub step: u64,
    /// The app's world. Read it, do not move circles: the report's final overlaps are this
    /// sample's when the run ends on it.
    pub world: &'a mut World,
}

impl Sample<'_> {
    /// Every circle, in spawn order: a [`snapshot`], taken when asked for (a run that only
    /// counts steps never copies its millions of circles).
    pub fn circles(&mut self) -> Vec<CircleState> {
        snapshot(self.world)
    }
}

/// How often [`run_steps`] samples the state by default: after every step up to 10 000
/// circles, after every 10th above (the report's overlaps are measured on those samples).
pub fn default_sampling(circles: usize) -> u64 {
    if circles <= 10_000 { 1 } else { 10 }
}

/// Steps `app` `steps` times, timing the steps alone. After every `sample_every`-th step (and
/// the last) it measures the overlaps and hands a [`Sample`] to `observe`, outside the timed
/// stepping. Returns the report of the run, with `source` as its source.
pub fn run_steps(
    app: &mut App,
    source: &str,
    steps: u64,
    sample_every: u64,
    mut observe: impl FnMut(Sample),
) -> Report {
    let mut progress = Progress::start(app.world_mut());
    let until = app.world().resource::<StepTotals>().steps + steps;
    advance(
        app,
        &mut progress,
        until,
        sample_every,
        || false,
        &mut observe,
    );
    sample_end(app, &mut progress, sample_every, observe);
    Report::new(app.world_mut(), source, &progress)
}

/// What a run has gathered besides the world's own counters: what its report is made of, and
/// what a checkpoint keeps so that a resumed run reports the whole run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    /// Energy, momentum and counts when the run began.
    pub before: Totals,
    /// Circles the scene's drop rules had dropped when the run began: those dropped after
    /// bring their energy and momentum into the run ([`dropped_totals`]). Kept in checkpoints
    /// as their last field.
    #[serde(skip)]
    pub drops_before: usize,
    /// Overlaps seen in the samples so far.
    pub overlaps: Overlaps,
    /// Wall-clock time spent stepping so far.
    pub stepping: Duration,
    /// The step of the last sample and the overlaps it measured, which the report's final
    /// overlaps are when the run ends there (measuring them again costs a second at 5 M
    /// circles). Not kept in checkpoints: a resumed run has not sampled yet.
    #[serde(skip)]
    pub last_sample: Option<(u64, Overlaps)>,
}

impl Progress {
    /// A run beginning from the world's state now.
    pub fn start(world: &mut World) -> Self {
        Self {
            before: totals(world),
            drops_before: world.resource::<Dropped>().count,
            ..Self::default()
        }
    }
}

/// Steps `app` until its [`StepTotals`] reach `until`, or until `stop` says so after a step,
/// timing the steps alone into `progress`. While it steps, the app's
/// [`CircleDiagnostics`](crate::game::diagnostics::CircleDiagnostics) are not measured
/// ([`Measuring::AfterSpawn`]; the run takes its own totals), so they are stale until the app's
/// next step after this. After every step whose number is a multiple of `sample_every` it
/// measures the overlaps into `progress` and hands a [`Sample`] to `observe`. Step numbers count from the start of the run, so a run resumed from a
/// checkpoint samples exactly the steps the whole run would have. Returns whether `stop` ended
/// it early, or was raised by the end (it may have cut the last step short).
pub fn advance(
    app: &mut App,
    progress: &mut Progress,
    until: u64,
    sample_every: u64,
    stop: impl Fn() -> bool,
    mut observe: impl FnMut(Sample),
) -> bool {
    let measuring = app
        .world_mut()
        .get_resource_mut::<Measuring>()
        .map(|mut measuring| std::mem::replace(&mut *measuring, Measuring::AfterSpawn));
    let stopped = loop {
        let step = app.world().resource::<StepTotals>().steps;
        if step >= until {
            break stop();
        }
        if stop() {
            break true;
        }
        let start = Instant::now();
        app.update();
        progress.stepping += start.elapsed();
        if (step + 1).is_multiple_of(sample_every.max(1)) {
            take_sample(app.world_mut(), progress, &mut observe);
        }
    };
    if let Some(measuring) = measuring {
        app.world_mut().insert_resource(measuring);
    }
    stopped
}

/// Samples the final state of a run that [`advance`] did not sample (its last step not a
/// multiple of `sample_every`), so the report covers the state it ends in. A checkpoint keeps
/// the progress from before this, as the whole run would not have sampled here.
pub fn sample_end(
    app: &mut App,
    progress: &mut Progress,
    sample_every: u64,
    mut observe: impl FnMut(Sample),
) {
    let step = app.world().resource::<StepTotals>().steps;
    if !step.is_multiple_of(sample_every.max(1)) {
        take_sample(app.world_mut(), progress, &mut observe);
    }
}

/// The overlaps between the circles of `world` that meet.
fn overlaps_in(world: &mut World, arena: &Arena) -> Overlaps {
    let mut circles = world.query::<LayeredDisc>();
    Overlaps::measure_layered(circles.iter(world).map(layered_disc), arena)
}

fn take_sample(world: &mut World, progress: &mut Progress, observe: &mut impl FnMut(Sample)) {
    let step = world.resource::<StepTotals>().steps;
    let arena = *world.resource::<Arena>();
    let overlaps = overlaps_in(world, &arena);
    progress.overlaps.add(overlaps);
    progress.last_sample = Some((step, overlaps));
    observe(Sample { step, world });
}

/// The first circle of `world` (its index in spawn order) whose position, velocity or turning
/// has left the range every reader holds values to ([`check_motion`]), and what is wrong.
/// Inputs at the range's edge can drive a run past it; our outputs of such a state would be
/// refused by our own readers, so `moving_circles run` writes none (as for a non-finite one).
pub fn out_of_range(world: &mut World) -> Option<(usize, FieldError)> {
    let mut circles = world.query::<Parts>();
    circles
        .iter(world)
        .enumerate()
        .find_map(|(i, parts)| check_motion(&from_components(parts)).err().map(|e| (i, e)))
}

/// Mechanical energy, momentum and counts of the world's circles under its arena and gravity.
fn totals(world: &mut World) -> Totals {
    let (arena, gravity) = (
        *world.resource::<Arena>(),
        world.resource::<Effects>().gravity,
    );
    let mut circles = world.query::<(Parts, Option<&Inertia>)>();
    let measured = circles.iter(world).map(|(parts, own)| {
        let c = from_components(parts);
        let turning = (
            c.angular_velocity,
            inertia(own.map(|i| i.0), c.mass, c.radius),
        );
        (c.position, c.velocity, c.mass, turning)
    });
    Totals::measure(measured, &arena, gravity)
}

/// What a headless run did. Field names and meanings are stable: other tools read them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Where the circles came from (scene or particle file).
    pub source: String,
    /// Number of circles.
    pub n: usize,
    /// Circles the spawn rules asked for (random plus explicit).
    pub requested: usize,
    /// Solver name, e.g. `discrete` or `substeps=4`.
    pub solver: String,
    /// `walls` or `periodic`.
    pub boundary: String,
    /// The effects that had systems.
    pub effects: Vec<String>,
    /// Fixed step in seconds.
    pub dt: f64,
    /// Fixed steps advanced.
    pub steps: u64,
    /// Simulated seconds advanced.
    pub sim_seconds: f64,
    /// Wall-clock seconds of stepping only (not loading or spawning).
    pub wall_seconds: f64,
    /// `wall_seconds / steps` in milliseconds.
    pub ms_per_step: f64,
    /// Mechanical energy (kinetic, plus potential under gravity) at the start.
    pub energy_initial: f64,
    /// Mechanical energy the circles dropped during the run brought in as they entered (0
    /// without drop rules).
    pub energy_added: f64,
    /// Mechanical energy at the end.
    pub energy_final: f64,
    /// `(final - expected) / |expected|` with `expected = initial + added`, or the absolute
    /// change when the expected energy is 0 or so small that the ratio overflows.
    pub energy_drift: f64,
    /// Total momentum `[x, y]` at the start.
    pub momentum_initial: [f64; 2],
    /// Momentum the dropped circles brought in.
    pub momentum_added: [f64; 2],
    /// Total momentum at the end.
    pub momentum_final: [f64; 2],
    /// Angular momentum about the origin at the start, `Σ (m x × v + I ω)`.
    pub angular_momentum_initial: f64,
    /// Angular momentum the dropped circles brought in.
    pub angular_momentum_added: f64,
    /// The same at the end.
    pub angular_momentum_final: f64,
    /// Deepest overlap after any (sampled) step, as a fraction of the pair's smaller radius.
    pub max_penetration: f64,
    /// Mean overlap of the overlapping pairs seen after (sampled) steps, same units.
    pub mean_penetration: f64,
    /// Deepest overlap in the final state (at rest, for a pile that settled), same units.
    pub final_penetration: f64,
    /// Kinetic energy at the end (what a pile that should have settled has left).
    pub kinetic_final: f64,
    /// Energy of turning at the end, `Σ ½ I ω²` (in `energy_final`, not in `kinetic_final`).
    pub rotational_final: f64,
    /// Centres outside the arena at the end.
    pub escaped: usize,
    /// Circles with a non-finite position or velocity at the end.
    pub non_finite: usize,
    /// Circle-circle collisions (impulses).
    pub pair_collisions: u64,
    /// Wall hits.
    pub wall_collisions: u64,
    /// Compressibility factor `P·A / (N·kT)` from the collisional virial.
    pub z: Option<f64>,
    /// Compressibility factor from the momentum the walls took up (walls only).
    pub z_wall: Option<f64>,
    /// Steps of `swept` / `exact` whose event budget ran out (rest of the step free flight).
    pub budget_exhausted: u64,
    /// Circles asleep at the end.
    pub sleeping: usize,
    /// Whether a signal (SIGINT, SIGTERM) ended the run before its length: the report is of
    /// the steps done.
    pub interrupted: bool,
}

impl Report {
    /// Whether every circle stayed finite and every measure is a finite number (inputs within
    /// the one physical range keep them so; this is the check that they did).
    pub fn is_finite(&self) -> bool {
        let numbers = [
            self.sim_seconds,
            self.energy_initial,
            self.energy_added,
            self.energy_final,
            self.energy_drift,
            self.momentum_initial[0],
            self.momentum_initial[1],
            self.momentum_added[0],
            self.momentum_added[1],
            self.angular_momentum_added,
            self.momentum_final[0],
            self.momentum_final[1],
            self.angular_momentum_initial,
            self.angular_momentum_final,
            self.max_penetration,
            self.mean_penetration,
            self.final_penetration,
            self.kinetic_final,
            self.rotational_final,
            self.z.unwrap_or(0.0),
            self.z_wall.unwrap_or(0.0),
        ];
        self.non_finite == 0 && numbers.iter().all(|x| x.is_finite())
    }

    /// The report of the run `progress` belongs to, as `world` stands now.
    pub fn new(world: &mut World, source: &str, progress: &Progress) -> Self {
        let after = totals(world);
        let Progress {
            before,
            drops_before,
            overlaps,
            stepping,
            ..
        } = *progress;
        let elapsed = *world.resource::<StepTotals>();
        let pairs = *world.resource::<PairCollisions>();
        let walls = *world.resource::<WallCollisions>();
        let arena = *world.resource::<Arena>();
        let final_overlaps = match progress.last_sample {
            Some((step, overlaps)) if step == elapsed.steps => overlaps,
            _ => overlaps_in(world, &arena),
        };
        let sleeping = world
            .query::<&Sleep>()
            .iter(world)
            .filter(|s| s.asleep)
            .count();
        let registry = world.resource::<EffectRegistry>();
        let pressure = Pressure::measure(
            &elapsed,
            &pairs,
            &walls,
            after.count,
            after.kinetic_energy,
            &arena,
        );
        let wall_seconds = stepping.as_secs_f64();
        let added = dropped_totals(world, drops_before);
        let expected = before.energy() + added.energy();
        Report {
            source: source.to_owned(),
            n: after.count,
            requested: world.resource::<SpawnReport>().requested,
            solver: world.resource::<Solver>().to_string(),
            boundary: arena.boundary.to_string(),
            effects: Effect::ALL
                .into_iter()
                .filter(|&e| registry.is_scheduled(e))
                .map(|e| e.name().to_owned())
                .collect(),
            dt: world.resource::<Time<Fixed>>().timestep().as_secs_f64(),
            steps: elapsed.steps,
            sim_seconds: elapsed.sim_seconds,
            wall_seconds,
            ms_per_step: if elapsed.steps > 0 {
                1e3 * wall_seconds / elapsed.steps as f64
            } else {
                0.0
            },
            energy_initial: before.energy(),
            energy_final: after.energy(),
            energy_added: added.energy(),
            energy_drift: relative_change(expected, after.energy()),
            momentum_initial: before.momentum.to_array(),
            momentum_added: added.momentum.to_array(),
            momentum_final: after.momentum.to_array(),
            angular_momentum_initial: before.angular_momentum,
            angular_momentum_added: added.angular_momentum,
            angular_momentum_final: after.angular_momentum,
            max_penetration: overlaps.max,
            mean_penetration: overlaps.mean(),
            final_penetration: final_overlaps.max,
            kinetic_final: after.kinetic_energy,
            rotational_final: after.rotational_energy,
            escaped: after.escaped,
            non_finite: after.non_finite,
            pair_collisions: pairs.count,
            wall_collisions: walls.count,
            z: pressure.z_virial,
            z_wall: pressure.z_wall,
            budget_exhausted: world.resource::<EngineState>().budget_exhausted,
            sleeping,
            interrupted: false,
        }
    }
}
