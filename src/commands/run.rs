//! `moving_circles run`: load a scene or particle file, apply the command line's overrides
//! (solver, or `auto` within a tolerance; step; seed; length), step it headless with a progress
//! bar on a terminal, print a summary and write the report and the final state.

use std::path::PathBuf;
use std::str::FromStr;

use anyhow::{Context, bail};

use crate::accuracy::auto::choose_solver;
use crate::arena::Boundary;
use crate::circle::snapshot;
use crate::config::{CirclesConfig, ParseSolverError, Solver};
use crate::io::{check_output_path, same_output, say, write_atomically};
use crate::run::{Report, default_sampling, headless_app, run_steps};
use crate::scene::{Scene, particles};
use crate::spawn::SpawnReport;

/// Most threads `--threads` may ask for: far more than any machine this runs on has cores, and
/// few enough that starting them cannot exhaust the process.
pub const MAX_THREADS: u16 = 1024;

/// Where the circles come from.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A scene file (RON).
    Scene(PathBuf),
    /// A particle file, in the unit square with this boundary (walls by default).
    Particles(PathBuf, Option<Boundary>),
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
    /// Where the JSON report goes.
    pub report: Option<PathBuf>,
    /// Where the final state goes (particle format).
    pub dump: Option<PathBuf>,
    /// Threads of the parallel parts of a step (results do not depend on it).
    pub threads: Option<u16>,
}

/// Runs `options` to the end: loads, steps, prints the summary, writes the outputs.
pub fn run(options: RunOptions) -> anyhow::Result<()> {
    check_outputs(&options)?;
    let (mut config, source) = load(&options.input)?;
    if let Some(dt) = options.dt {
        config.dt = dt;
    }
    if let Some(seed) = options.seed {
        config.spawn.seed = seed;
    }
    // The overrides go through the same check as the file did.
    config.check()?;
    config.solver = choose(&config, options.solver, options.tolerance)?;
    let steps = match options.length {
        Length::Steps(0) => bail!("--steps must be at least 1"),
        Length::Steps(steps) => steps,
        Length::Seconds(t) if t.is_finite() && t > 0.0 && t / config.dt <= 1e12 => {
            (t / config.dt).ceil() as u64
        }
        Length::Seconds(t) => {
            bail!("--seconds must be positive, finite and at most 1e12 steps long, got {t}")
        }
    };
    if let Some(threads) = options.threads {
        // Set up before the App, whose task pool plugin keeps a pool that already exists.
        bevy::tasks::ComputeTaskPool::get_or_init(|| {
            bevy::tasks::TaskPoolBuilder::new()
                .num_threads(threads.into())
                .build()
        });
    }
    let mut app = headless_app(config);
    let spawn = *app.world().resource::<SpawnReport>();
    if spawn.placed < spawn.requested {
        eprintln!(
            "moving_circles: warning: placed {} of {} circles; the arena has no room for more",
            spawn.placed, spawn.requested
        );
    }
    let bar = indicatif::ProgressBar::new(steps).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}")
            .expect("valid template"),
    );
    let report = run_steps(
        &mut app,
        &source,
        steps,
        default_sampling(spawn.placed),
        |s| bar.set_position(s.step),
    );
    bar.finish_and_clear();

    print_summary(&report);
    if let Some(path) = &options.report {
        let json = serde_json::to_string_pretty(&report).context("serialising the report")?;
        write_atomically(path, (json + "\n").as_bytes())
            .with_context(|| format!("writing the report to {}", path.display()))?;
    }
    if let Some(path) = &options.dump {
        let state = snapshot(app.world_mut());
        write_atomically(path, particles::format(&state).as_bytes())
            .with_context(|| format!("writing the final state to {}", path.display()))?;
    }
    Ok(())
}

/// Refuses, before any work, outputs that could not be written or would clobber something:
/// paths that are not regular files (devices, directories, links), missing folders, and the
/// report and the dump on one file.
fn check_outputs(options: &RunOptions) -> anyhow::Result<()> {
    for (flag, path) in [("--report", &options.report), ("--dump", &options.dump)] {
        if let Some(path) = path {
            check_output_path(path).with_context(|| flag.to_owned())?;
        }
    }
    if let (Some(report), Some(dump)) = (&options.report, &options.dump)
        && same_output(report, dump)
    {
        bail!(
            "--report and --dump name the same file, {}: one would replace the other",
            report.display()
        );
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
