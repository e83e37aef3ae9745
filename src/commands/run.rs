//! `moving_circles run`: load a scene or particle file (or resume a checkpoint), apply the
//! command line's overrides (solver, or `auto` within a tolerance; step; seed; length), step it
//! headless with a progress bar on a terminal, print a summary and write the report, the final
//! state and checkpoints. SIGINT and SIGTERM end it after the current step with all of those
//! written; a second signal ends it at once.

use std::path::PathBuf;
use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::{Context, bail};
use bevy::prelude::App;

use crate::accuracy::auto::choose_solver;
use crate::arena::Boundary;
use crate::checkpoint::Checkpoint;
use crate::circle::snapshot;
use crate::config::{CirclesConfig, ParseSolverError, Placement, Solver};
use crate::io::{check_output_path, same_output, say, write_atomically};
use crate::run::{Progress, Report, advance, default_sampling, headless_app, sample_end};
use crate::scene::{Scene, particles};
use crate::schedule::StepTotals;
use crate::spawn::SpawnReport;

/// Most threads `--threads` may ask for: far more than any machine this runs on has cores, and
/// few enough that starting them cannot exhaust the process.
pub const MAX_THREADS: u16 = 1024;
/// Most steps one run may ask for: about three hours at a microsecond per step, the cost of a
/// handful of circles; a request for more is a typo for a shorter `--dt` or `--seconds`.
pub const MAX_STEPS: u64 = 10_000_000_000;
/// Circles above which `run` says it is placing them before it starts (placing millions takes
/// seconds to minutes).
const ANNOUNCE_SPAWN_FROM: usize = 1_000_000;
/// The same for a `pack` placement, whose compression takes about a second per 5000 circles.
const ANNOUNCE_PACK_FROM: usize = 20_000;

/// Where the circles come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A scene file (RON).
    Scene(PathBuf),
    /// A particle file, in the unit square with this boundary (walls by default).
    Particles(PathBuf, Option<Boundary>),
    /// A checkpoint, to go on from.
    Resume(PathBuf),
}

/// How long to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// Simulated seconds, rounded up to whole steps.
    Seconds(f64),
    /// Fixed steps.
    Steps(u64),
}

/// A fixed solver, or `auto`: the cheapest that meets a tolerance on a short calibration run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SolverChoice {
    /// This solver.
    Fixed(Solver),
    /// Chosen by measurement.
    Auto,
}

impl FromStr for SolverChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Self::Auto);
        }
        s.parse()
            .map(Self::Fixed)
            .map_err(|e: ParseSolverError| format!("{e}, or `auto`"))
    }
}

/// Everything `run` is asked to do.
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// The circles.
    pub input: Input,
    /// Overrides the scene's solver.
    pub solver: Option<SolverChoice>,
    /// With `auto`: the largest acceptable error in radii.
    pub tolerance: Option<f64>,
    /// Overrides the fixed step.
    pub dt: Option<f64>,
    /// How long.
    pub length: Length,
    /// Overrides the placement seed.
    pub seed: Option<u64>,
    /// Overrides where the scene's circles are spawned.
    pub placement: Option<Placement>,
    /// Overrides the scene's count with an area fraction to fill.
    pub area_fraction: Option<f64>,
    /// Where the JSON report goes.
    pub report: Option<PathBuf>,
    /// Where the final state goes (particle format).
    pub dump: Option<PathBuf>,
    /// Threads of the parallel parts of a step (results do not depend on it).
    pub threads: Option<u16>,
    /// Where checkpoints go: at the end, when interrupted, and every `every` steps.
    pub checkpoint: Option<PathBuf>,
    /// Steps between checkpoints (counted from the start of the whole run).
    pub every: Option<u64>,
}

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finished {
    /// It ran its length.
    Completed,
    /// A signal stopped it after a step; everything asked for was written.
    Interrupted {
        /// The signal's number (2 for SIGINT, 15 for SIGTERM).
        signal: i32,
    },
}

impl Finished {
    /// The process's exit status: 0, or 128 + the signal as shells report it (130, 143).
    pub fn exit_code(self) -> u8 {
        match self {
            Self::Completed => 0,
            Self::Interrupted { signal } => 128u8.saturating_add(signal as u8),
        }
    }
}

/// Runs `options` to the end (or to a signal): loads, steps, prints the summary, writes the
/// outputs.
pub fn run(options: RunOptions) -> anyhow::Result<Finished> {
    check_outputs(&options)?;
    if options.every == Some(0) {
        bail!("--every must be at least 1");
    }
    let interrupts = Interrupts::install()?;
    let (mut app, mut progress, source, dt) = match &options.input {
        Input::Resume(path) => {
            let spawn = options.placement.is_some() || options.area_fraction.is_some();
            if options.solver.is_some() || options.dt.is_some() || options.seed.is_some() || spawn {
                bail!(
                    "--resume goes on with the checkpoint's settings: no --solver, --dt, --seed, \
                     --placement or --area-fraction"
                );
            }
            let checkpoint = Checkpoint::read(path)?;
            let source = checkpoint.source.clone();
            let origin = path.display().to_string();
            let (app, progress) = checkpoint.resume(&origin)?;
            let dt = app
                .world()
                .resource::<bevy::time::Time<bevy::time::Fixed>>();
            let dt = dt.timestep().as_secs_f64();
            (app, progress, source, dt)
        }
        input => {
            let (config, source) = configure(input, &options)?;
            let dt = config.dt;
            set_threads(options.threads);
            let mut app = start(config, &source)?;
            let progress = Progress::start(app.world_mut());
            (app, progress, source, dt)
        }
    };
    let steps = steps_of(options.length, dt)?;
    let first = app.world().resource::<StepTotals>().steps;
    let until = first.saturating_add(steps);
    let bar = indicatif::ProgressBar::new(steps).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}")
            .expect("valid template"),
    );
    let sampling = default_sampling(app.world().resource::<crate::spawn::SpawnReport>().placed);
    // What could not be written; the other outputs are written all the same.
    let mut failed: Vec<anyhow::Error> = Vec::new();
    let stopped = loop {
        let now = app.world().resource::<StepTotals>().steps;
        let next = match (&options.checkpoint, options.every) {
            (Some(_), Some(every)) => until.min((now / every + 1).saturating_mul(every)),
            _ => until,
        };
        let stop = || interrupts.raised().is_some();
        let stopped = advance(&mut app, &mut progress, next, sampling, stop, |s| {
            bar.set_position(s.step - first)
        });
        if stopped || next >= until {
            break stopped;
        }
        if let Some(path) = &options.checkpoint
            && let Err(e) = write_checkpoint(&mut app, &source, &progress, path)
        {
            // A periodic checkpoint that cannot be written (a full disk) ends the run here,
            // with the report and the dump of where it got to.
            failed.push(e);
            break true;
        }
    };
    let checkpoint_failed = !failed.is_empty();
    bar.finish_and_clear();

    let mut ended = progress;
    sample_end(&mut app, &mut ended, sampling, |_| {});
    let mut report = Report::new(app.world_mut(), &source, &ended);
    report.interrupted = stopped;
    print_summary(&report);
    if !report.is_finite() {
        bail!(
            "the run's state became non-finite ({} circles); nothing was written",
            report.non_finite
        );
    }
    if let Some(path) = &options.report {
        let json = serde_json::to_string_pretty(&report).context("serialising the report")?;
        if let Err(e) = write_atomically(path, (json + "\n").as_bytes()) {
            failed.push(
                anyhow::Error::new(e).context(format!("writing the report to {}", path.display())),
            );
        }
    }
    if let Some(path) = &options.dump {
        let state = snapshot(app.world_mut());
        if let Err(e) = write_atomically(path, particles::format(&state).as_bytes()) {
            failed.push(
                anyhow::Error::new(e)
                    .context(format!("writing the final state to {}", path.display())),
            );
        }
    }
    // Once failed, the checkpoint is not tried again: the run stopped where it failed.
    if let Some(path) = &options.checkpoint
        && !checkpoint_failed
        && let Err(e) = write_checkpoint(&mut app, &source, &progress, path)
    {
        failed.push(e);
    }
    if !failed.is_empty() {
        let all: Vec<String> = failed.iter().map(|e| format!("{e:#}")).collect();
        bail!("{} (the other outputs were written)", all.join("; "));
    }
    Ok(match interrupts.raised() {
        Some(signal) if stopped => {
            say(format_args!(
                "interrupted by signal {signal} after step {}; outputs written",
                report.steps
            ));
            Finished::Interrupted { signal }
        }
        _ => Finished::Completed,
    })
}

/// SIGINT and SIGTERM, caught: the first asks the run to stop after the current step; a second
/// ends the process at once with 130 / 143, leaving every output as it was (each is replaced
/// whole or not at all).
struct Interrupts {
    signal: Arc<AtomicUsize>,
}

impl Interrupts {
    fn install() -> anyhow::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        let once = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for (number, code) in [(SIGINT, 130), (SIGTERM, 143)] {
            // Handlers run in the order registered: the exit checks the flag before it is set.
            flag::register_conditional_shutdown(number, code, Arc::clone(&once))
                .and_then(|_| flag::register(number, Arc::clone(&once)))
                .and_then(|_| flag::register_usize(number, Arc::clone(&signal), number as usize))
                .context("installing the signal handlers")?;
        }
        Ok(Self { signal })
    }

    /// The signal that asked the run to stop, if one did.
    fn raised(&self) -> Option<i32> {
        match self.signal.load(Ordering::Relaxed) {
            0 => None,
            n => Some(n as i32),
        }
    }
}

fn write_checkpoint(
    app: &mut App,
    source: &str,
    progress: &Progress,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let bytes = Checkpoint::take(app.world_mut(), source, progress).to_bytes();
    write_atomically(path, &bytes)
        .with_context(|| format!("writing the checkpoint to {}", path.display()))
}

/// The configuration of a scene or particle file with the command line's overrides, checked,
/// and the report's name for it.
fn configure(input: &Input, options: &RunOptions) -> anyhow::Result<(CirclesConfig, String)> {
    let (mut config, source) = load(input)?;
    if let Some(dt) = options.dt {
        config.dt = dt;
    }
    if let Some(seed) = options.seed {
        config.spawn.seed = seed;
    }
    if let Some(placement) = options.placement {
        config.spawn.placement = placement;
    }
    if let Some(fraction) = options.area_fraction {
        config.spawn.area_fraction = Some(fraction);
    }
    // The overrides go through the same check as the file did.
    config.check()?;
    config.solver = choose(&config, options.solver, options.tolerance)?;
    Ok((config, source))
}

/// The steps `length` asks for at `dt`, within [`MAX_STEPS`].
fn steps_of(length: Length, dt: f64) -> anyhow::Result<u64> {
    Ok(match length {
        Length::Steps(steps) if (1..=MAX_STEPS).contains(&steps) => steps,
        Length::Steps(steps) => bail!("--steps must be from 1 to {MAX_STEPS}, got {steps}"),
        Length::Seconds(t) if t.is_finite() && t > 0.0 && t / dt <= MAX_STEPS as f64 => {
            (t / dt).ceil() as u64
        }
        Length::Seconds(t) => bail!(
            "--seconds must be positive and at most {MAX_STEPS} steps of {dt} s long, got {t}"
        ),
    })
}

fn set_threads(threads: Option<u16>) {
    if let Some(threads) = threads {
        // Set up before the App, whose task pool plugin keeps a pool that already exists.
        bevy::tasks::ComputeTaskPool::get_or_init(|| {
            bevy::tasks::TaskPoolBuilder::new()
                .num_threads(threads.into())
                .build()
        });
    }
}

/// The headless app of `config` from `source`, its circles placed (saying so first when that
/// takes a while, and afterwards when not all fit).
fn start(config: CirclesConfig, source: &str) -> anyhow::Result<App> {
    let placing = config.spawn.target_count(&config.arena);
    let how = match config.spawn.placement {
        Placement::Pack => "compressing",
        Placement::Lattice => "placing on a lattice",
        Placement::Random => "placing at random",
    };
    let announce_from = match config.spawn.placement {
        Placement::Pack => ANNOUNCE_PACK_FROM,
        _ => ANNOUNCE_SPAWN_FROM,
    };
    if placing >= announce_from {
        eprintln!("moving_circles: {how} {placing} circles (this takes a while)");
    }
    let app = headless_app(config);
    let spawn = app.world().resource::<SpawnReport>();
    if let Some(refused) = &spawn.refused {
        bail!("{source}: cannot spawn the scene's circles: {refused}");
    }
    if spawn.placed < spawn.requested {
        eprintln!(
            "moving_circles: warning: placed {} of {} circles; the arena has no room for more",
            spawn.placed, spawn.requested
        );
    }
    Ok(app)
}

/// Refuses, before any work, outputs that could not be written or would clobber something:
/// paths that are not regular files (devices, directories, links), missing folders, names too
/// long for the temporary file, two outputs on one file, and an output on the run's input.
fn check_outputs(options: &RunOptions) -> anyhow::Result<()> {
    let outputs = [
        ("--report", &options.report),
        ("--dump", &options.dump),
        ("--checkpoint", &options.checkpoint),
    ];
    for (flag, path) in outputs {
        if let Some(path) = path {
            check_output_path(path).with_context(|| flag.to_owned())?;
        }
    }
    for (k, (flag, path)) in outputs.iter().enumerate() {
        for (other, other_path) in &outputs[k + 1..] {
            if let (Some(a), Some(b)) = (path, other_path)
                && same_output(a, b)
            {
                bail!(
                    "{flag} and {other} name the same file, {}: one would replace the other",
                    a.display()
                );
            }
        }
    }
    // An output must not replace the run's own input; a checkpoint may replace the one it
    // resumes (written whole, it is the same run further on).
    let (input_flag, input) = match &options.input {
        Input::Scene(path) => ("--scene", path),
        Input::Particles(path, _) => ("--particles", path),
        Input::Resume(path) => ("--resume", path),
    };
    for (flag, path) in outputs {
        let resumed_again = flag == "--checkpoint" && input_flag == "--resume";
        if let Some(path) = path
            && !resumed_again
            && same_output(path, input)
        {
            bail!(
                "{flag} names the input of {input_flag}, {}: it would be replaced",
                path.display()
            );
        }
    }
    if options.every.is_some() && options.checkpoint.is_none() {
        bail!("--every N goes with --checkpoint PATH");
    }
    Ok(())
}

/// The configuration and the report's name for `input`.
fn load(input: &Input) -> anyhow::Result<(CirclesConfig, String)> {
    Ok(match input {
        Input::Scene(path) => (Scene::load(path)?, path.display().to_string()),
        Input::Particles(path, boundary) => {
            let boundary = boundary.unwrap_or_default();
            let circles = particles::read(path, boundary)?;
            (
                particles::to_config(circles, boundary),
                path.display().to_string(),
            )
        }
        Input::Resume(_) => unreachable!("a checkpoint is resumed, not loaded as a scene"),
    })
}

/// The solver to run: the scene's, the one asked for, or the cheapest within `tolerance`.
fn choose(
    config: &CirclesConfig,
    choice: Option<SolverChoice>,
    tolerance: Option<f64>,
) -> anyhow::Result<Solver> {
    Ok(match (choice, tolerance) {
        (Some(SolverChoice::Auto), Some(tolerance)) if tolerance.is_finite() && tolerance > 0.0 => {
            let (choice, measured) = choose_solver(config, tolerance);
            for c in &measured {
                let chosen = if c.solver == choice {
                    "  <- chosen"
                } else {
                    ""
                };
                eprintln!(
                    "auto: {:<12} error {:.2e}  {:.4} ms/step{chosen}",
                    c.solver.to_string(),
                    c.error,
                    c.ms_per_step,
                );
            }
            choice
        }
        (Some(SolverChoice::Auto), Some(t)) => {
            bail!("--tolerance must be a positive number, got {t}")
        }
        (Some(SolverChoice::Auto), None) => {
            bail!("--solver auto needs --tolerance X (the largest acceptable error, in radii)")
        }
        (_, Some(_)) => bail!("--tolerance goes with --solver auto"),
        (Some(SolverChoice::Fixed(solver)), None) => solver,
        (None, None) => config.solver,
    })
}

fn print_summary(r: &Report) {
    say(format_args!(
        "{} circles, {}, {} steps of {:.6} s in {:.3} s ({:.4} ms/step)",
        r.n, r.solver, r.steps, r.dt, r.wall_seconds, r.ms_per_step
    ));
    say(format_args!(
        "energy drift {:+.3e}, max penetration {:.3e}, collisions {} pair / {} wall, escaped {}, non-finite {}",
        r.energy_drift,
        r.max_penetration,
        r.pair_collisions,
        r.wall_collisions,
        r.escaped,
        r.non_finite
    ));
}
