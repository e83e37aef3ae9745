//! The `moving_circles` binary: opens the app (feature `render`) on a scene, or runs headless
//! batch work (`run`, `systems`). Argument parsing and error reporting live here; the work itself
//! is in the library (`moving_circles::run`, `moving_circles::scene`).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use bevy::prelude::default;
use clap::{Args, Parser, Subcommand};
use moving_circles::prelude::*;
use moving_circles::run::{Report, headless_app, run_steps, snapshot};
use moving_circles::scene::{DT_RANGE, particles};
use moving_circles::schedule::scheduled_systems;

/// Writes a line to stdout. A closed pipe (`moving_circles run … | head -1`) ends the reader's
/// interest, not our work: the files we were asked for are still written, so write errors on
/// stdout are ignored instead of panicking as `println!` does.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}

/// Moving, colliding circles. Without a subcommand, opens the app.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    app: AppArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene or particle file headless and report (no window).
    Run(RunArgs),
    /// Run the accuracy study: every solver and step on a set of scenes, measured against
    /// `exact`; prints a table and writes accuracy.csv and accuracy.svg.
    Accuracy {
        /// Folder for accuracy.csv and accuracy.svg.
        #[arg(long, value_name = "DIR", default_value = "out")]
        out: PathBuf,
        /// Folder the study's scenes (gas1k, gas, billiards, fast) are read from.
        #[arg(long, value_name = "DIR", default_value = "assets/scenes")]
        scenes: PathBuf,
        /// One step size and shorter runs: a smoke test of the study, not a measurement.
        #[arg(long)]
        quick: bool,
    },
    /// Print the systems a scene schedules, one per line.
    Systems {
        /// The scene (RON).
        #[arg(long, value_name = "PATH")]
        scene: PathBuf,
    },
}

/// Options of the windowed app.
#[derive(Args, Debug)]
struct AppArgs {
    /// Scene file (RON) to open; the app reloads it when it changes. Default: the built-in
    /// `classic` scene.
    #[arg(long, value_name = "PATH")]
    scene: Option<PathBuf>,
    /// Number of random circles (overrides the scene).
    #[arg(long)]
    count: Option<usize>,
    /// Seed of the random placement (overrides the scene).
    #[arg(long)]
    seed: Option<u64>,
    /// Solver: `discrete`, `substeps=N`, `swept` or `exact` (overrides the scene).
    #[arg(long)]
    solver: Option<Solver>,
    /// Render `--frames` frames, save the window to this PNG and exit.
    #[arg(long, value_name = "PATH")]
    screenshot: Option<PathBuf>,
    /// Frames to render before `--screenshot` is taken.
    #[arg(long, default_value_t = 90, requires = "screenshot")]
    frames: u32,
}

#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["scene", "particles"])))]
#[command(group(clap::ArgGroup::new("length").required(true).args(["seconds", "steps"])))]
struct RunArgs {
    /// Scene file (RON).
    #[arg(long, value_name = "PATH")]
    scene: Option<PathBuf>,
    /// Particle file: `N`, then `rx ry vx vy radius mass r g b` per line, in the unit square.
    #[arg(long, value_name = "PATH")]
    particles: Option<PathBuf>,
    /// Solver: `discrete`, `substeps=N`, `swept`, `exact`, or `auto` (the cheapest that meets
    /// `--tolerance`, from a short calibration run). Default: the scene's, or `discrete`.
    #[arg(long, value_parser = parse_solver_choice)]
    solver: Option<SolverChoice>,
    /// With `--solver auto`: the largest acceptable error, as the larger of the position error
    /// against `exact` after a short calibration and the deepest overlap, both in radii.
    #[arg(long)]
    tolerance: Option<f64>,
    /// Boundary of a particle file's unit square: `walls` or `periodic`.
    #[arg(long, value_parser = parse_boundary)]
    boundary: Option<Boundary>,
    /// Fixed step in seconds, e.g. `0.01` or `1/60` (default: the scene's, or 1/60).
    #[arg(long, value_parser = parse_dt)]
    dt: Option<f64>,
    /// Simulated seconds to run (rounded up to whole steps).
    #[arg(long)]
    seconds: Option<f64>,
    /// Fixed steps to run.
    #[arg(long)]
    steps: Option<u64>,
    /// Seed of the random placement (overrides the scene).
    #[arg(long)]
    seed: Option<u64>,
    /// Write the report (JSON) here.
    #[arg(long, value_name = "PATH.json")]
    report: Option<PathBuf>,
    /// Write the final state here, in the particle format.
    #[arg(long, value_name = "PATH.txt")]
    dump: Option<PathBuf>,
    /// Threads for the parallel parts of a step (default: one per core). Results do not depend
    /// on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
}

/// A fixed solver, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SolverChoice {
    Fixed(Solver),
    Auto,
}

fn parse_solver_choice(s: &str) -> Result<SolverChoice, String> {
    if s == "auto" {
        return Ok(SolverChoice::Auto);
    }
    s.parse()
        .map(SolverChoice::Fixed)
        .map_err(|e: moving_circles::config::ParseSolverError| format!("{e}, or `auto`"))
}

fn parse_boundary(s: &str) -> Result<Boundary, String> {
    s.parse()
}

fn parse_dt(s: &str) -> Result<f64, String> {
    let value = match s.split_once('/') {
        Some((a, b)) => {
            let (a, b): (f64, f64) = (
                a.trim()
                    .parse()
                    .map_err(|_| format!("`{s}` is not a number or fraction"))?,
                b.trim()
                    .parse()
                    .map_err(|_| format!("`{s}` is not a number or fraction"))?,
            );
            a / b
        }
        None => s.parse().map_err(|_| format!("`{s}` is not a number"))?,
    };
    let (lo, hi) = DT_RANGE;
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(format!("must be between {lo} and {hi} seconds, got {s}"))
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Run(args)) => run(args),
        Some(Command::Systems { scene }) => systems(&scene),
        Some(Command::Accuracy { out, scenes, quick }) => accuracy(&out, &scenes, quick),
        None => return open_app(cli.app),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("moving_circles: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: RunArgs) -> anyhow::Result<()> {
    if args.scene.is_some() && args.boundary.is_some() {
        bail!("--boundary applies to --particles files; a scene sets its own `arena.boundary`");
    }
    let (mut config, source) = match (&args.scene, &args.particles) {
        (Some(scene), _) => (Scene::load(scene)?, scene.display().to_string()),
        (None, Some(file)) => {
            let boundary = args.boundary.unwrap_or_default();
            let circles = particles::read(file, boundary)?;
            (
                particle_config(circles, boundary),
                file.display().to_string(),
            )
        }
        (None, None) => unreachable!("clap requires --scene or --particles"),
    };
    if let Some(dt) = args.dt {
        config.dt = dt;
    }
    if let Some(seed) = args.seed {
        config.spawn.seed = seed;
    }
    match (args.solver, args.tolerance) {
        (Some(SolverChoice::Auto), Some(tolerance)) if tolerance.is_finite() && tolerance > 0.0 => {
            let (choice, measured) = moving_circles::accuracy::choose_solver(&config, tolerance);
            for c in &measured {
                eprintln!(
                    "auto: {:<12} error {:.2e}  {:.4} ms/step{}",
                    c.solver.to_string(),
                    c.error,
                    c.ms_per_step,
                    if c.solver == choice {
                        "  <- chosen"
                    } else {
                        ""
                    }
                );
            }
            config.solver = choice;
        }
        (Some(SolverChoice::Auto), Some(t)) => {
            bail!("--tolerance must be a positive number, got {t}")
        }
        (Some(SolverChoice::Auto), None) => {
            bail!("--solver auto needs --tolerance X (the largest acceptable error, in radii)")
        }
        (_, Some(_)) => bail!("--tolerance goes with --solver auto"),
        (Some(SolverChoice::Fixed(solver)), None) => config.solver = solver,
        (None, None) => {}
    }
    let steps = match (args.steps, args.seconds) {
        (Some(0), _) => bail!("--steps must be at least 1"),
        (Some(steps), _) => steps,
        (None, Some(t)) if t.is_finite() && t > 0.0 && t / config.dt <= 1e12 => {
            (t / config.dt).ceil() as u64
        }
        (None, Some(t)) => {
            bail!("--seconds must be positive, finite and at most 1e12 steps long, got {t}")
        }
        (None, None) => unreachable!("clap requires --seconds or --steps"),
    };

    if let Some(threads) = args.threads {
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
    let report = run_steps(&mut app, &source, steps, |done| bar.set_position(done));
    bar.finish_and_clear();

    print_summary(&report);
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report).context("serialising the report")?;
        particles::write_atomically(path, &(json + "\n"))
            .with_context(|| format!("writing the report to {}", path.display()))?;
    }
    if let Some(path) = &args.dump {
        let state = snapshot(app.world_mut());
        particles::write_atomically(path, &particles::format(&state))
            .with_context(|| format!("writing the final state to {}", path.display()))?;
    }
    Ok(())
}

/// A particle file's circles in the unit square, with the default effects.
fn particle_config(
    circles: Vec<moving_circles::spawn::CircleInit>,
    boundary: Boundary,
) -> CirclesConfig {
    CirclesConfig {
        arena: particles::unit_square(),
        spawn: SpawnConfig {
            count: 0,
            ..default()
        },
        effects: Effects {
            boundary,
            ..default()
        },
        circles,
        ..default()
    }
}

fn print_summary(r: &Report) {
    say!(
        "{} circles, {}, {} steps of {:.6} s in {:.3} s ({:.4} ms/step)",
        r.n,
        r.solver,
        r.steps,
        r.dt,
        r.wall_seconds,
        r.ms_per_step
    );
    say!(
        "energy drift {:+.3e}, max penetration {:.3e}, collisions {} pair / {} wall, escaped {}, non-finite {}",
        r.energy_drift,
        r.max_penetration,
        r.pair_collisions,
        r.wall_collisions,
        r.escaped,
        r.non_finite
    );
}

fn accuracy(out: &Path, scenes: &Path, quick: bool) -> anyhow::Result<()> {
    use moving_circles::accuracy::{
        compare, default_cases, plot, settings, to_csv, to_table, trace,
    };

    let cases = default_cases(scenes, quick)?;
    let settings = settings(quick);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let bar = indicatif::ProgressBar::new((cases.len() * (settings.len() + 1)) as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {msg}")
            .expect("valid template"),
    );
    let mut rows = Vec::new();
    for case in &cases {
        bar.set_message(format!("{}: exact reference", case.name));
        let reference = trace(case, Solver::Exact, 1.0 / 60.0);
        bar.inc(1);
        for &(solver, dt) in &settings {
            bar.set_message(format!("{}: {solver} at {:.0} Hz", case.name, 1.0 / dt));
            rows.push(compare(case, &trace(case, solver, dt), &reference));
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    say!("{}", to_table(&rows).trim_end());
    let csv = out.join("accuracy.csv");
    particles::write_atomically(&csv, &to_csv(&rows))
        .with_context(|| format!("writing {}", csv.display()))?;
    let svg = out.join("accuracy.svg");
    let partial = out.join(".accuracy.svg.partial");
    plot(&rows, &partial).map_err(|e| anyhow::anyhow!("drawing {}: {e}", svg.display()))?;
    std::fs::rename(&partial, &svg).with_context(|| format!("writing {}", svg.display()))?;
    say!("wrote {} and {}", csv.display(), svg.display());
    Ok(())
}

fn systems(scene: &Path) -> anyhow::Result<()> {
    let config = Scene::load(scene)?;
    // Only the step schedule the scene's solver runs.
    let idle_step = if config.solver.is_continuous() {
        "CircleStep"
    } else {
        "ContinuousStep"
    };
    let mut app = headless_app(config);
    for (schedule, system) in scheduled_systems(&mut app) {
        if schedule == idle_step {
            continue;
        }
        let name = system.rsplit("::").next().unwrap_or(&system);
        say!("{schedule} {name}");
    }
    Ok(())
}

#[cfg(feature = "render")]
fn app_config(args: &AppArgs) -> anyhow::Result<CirclesConfig> {
    let mut config = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => moving_circles::scene::classic(),
    };
    if let Some(count) = args.count {
        config.spawn.count = count;
        config.spawn.area_fraction = None;
    }
    if let Some(seed) = args.seed {
        config.spawn.seed = seed;
    }
    if let Some(solver) = args.solver {
        config.solver = solver;
    }
    Ok(config)
}

#[cfg(feature = "render")]
fn open_app(args: AppArgs) -> ExitCode {
    use moving_circles::render::{self, NO_WINDOW_HINT};

    let config = match app_config(&args) {
        Ok(config) => config,
        Err(e) => {
            eprintln!("moving_circles: {e:#}");
            return ExitCode::FAILURE;
        }
    };
    if let Some(problem) = render::display_problem() {
        eprintln!("{problem}");
        return ExitCode::FAILURE;
    }
    // A display that refuses the connection, or a missing Vulkan/GL driver, surfaces as a panic
    // deep inside winit or wgpu: say what failed in one line, then what to do instead.
    std::panic::set_hook(Box::new(|info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("unknown error");
        let location = info
            .location()
            .map(|l| format!(" ({l})"))
            .unwrap_or_default();
        eprintln!("moving_circles: the app stopped: {message}{location}\n\n{NO_WINDOW_HINT}");
    }));
    let options = render::AppOptions {
        scene_file: args.scene.clone(),
        screenshot: args.screenshot.map(|path| (path, args.frames)),
    };
    if render::app(config, options).run().is_success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

#[cfg(not(feature = "render"))]
fn open_app(_: AppArgs) -> ExitCode {
    eprintln!(
        "moving_circles was built without the `render` feature, so it has no window; \
         use `moving_circles run` or rebuild with default features"
    );
    ExitCode::FAILURE
}
