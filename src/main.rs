//! The `moving_circles` binary: parses the command line and calls the library's
//! [`commands`](moving_circles::cli) — the app (feature `render`) by default, or the
//! headless `run`, `accuracy` and `systems` — and turns an error into one line on stderr and a
//! non-zero exit.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::bail;
use clap::{Args, Parser, Subcommand};
use moving_circles::base::arena::Boundary;
use moving_circles::base::config::{DT_RANGE, Placement, Solver};
use moving_circles::base::error::printable;
use moving_circles::cli;
use moving_circles::cli::run::{Input, Length, RunOptions, SolverChoice};
use moving_circles::cli::run::{MAX_STEPS, MAX_THREADS};

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
    Run(Box<RunArgs>),
    /// Run the accuracy study: every solver and step on a set of scenes, measured against
    /// `exact`; prints a table and writes accuracy.csv and the figure (accuracy.svg and .png);
    /// then the pile scenes, measured on their own terms, into piles.csv.
    Accuracy {
        /// Folder for accuracy.csv, accuracy.svg, accuracy.png and piles.csv.
        #[arg(long, value_name = "DIR", default_value = "out")]
        out: PathBuf,
        /// Folder the study's scenes are read from: gas1k, gas, billiards, fast, rough_gas; galton
        /// and pile (pyramid with `--quick`).
        #[arg(long, value_name = "DIR", default_value = "assets/scenes")]
        scenes: PathBuf,
        /// One step size and shorter runs: a smoke test of the study, not a measurement.
        #[arg(long)]
        quick: bool,
        /// Runs at once, each a process (default: the cores).
        #[arg(long, value_name = "K")]
        jobs: Option<usize>,
    },
    /// Measure the hard-disk equation of state under `exact`: Z against area fraction in a
    /// periodic box, with block error bars, against Henderson's and Liu's equations; prints a
    /// table and writes eos.csv, eos.svg and eos.png.
    Eos {
        /// Folder for eos.csv, eos.svg and eos.png.
        #[arg(long, value_name = "DIR", default_value = "out")]
        out: PathBuf,
        /// Disks in the box (65536 for the liquid-hexatic region).
        #[arg(long, default_value_t = 4096, allow_negative_numbers = true, value_parser = parse_count)]
        n: usize,
        /// Area fractions, comma-separated, each in (0, 0.85]. Default: 0.05 to 0.65 by 0.05,
        /// then 0.68, 0.70, 0.72.
        #[arg(
            long,
            value_delimiter = ',',
            value_name = "ETA,...",
            allow_negative_numbers = true
        )]
        area_fractions: Option<Vec<f64>>,
        /// Collisions per disk run first and discarded (melting the lattice, equilibrating).
        #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
        equilibrate: f64,
        /// Blocks measured after that.
        #[arg(long, default_value_t = 10, allow_negative_numbers = true, value_parser = parse_count)]
        blocks: usize,
        /// Collisions per disk in each block.
        #[arg(long, default_value_t = 100.0, allow_negative_numbers = true)]
        block: f64,
        /// Seed of the velocities.
        #[arg(long, default_value_t = 1, allow_negative_numbers = true, value_parser = parse_seed)]
        seed: u64,
        /// Area fractions measured at once, each a process (default: the cores).
        #[arg(long, value_name = "K")]
        jobs: Option<usize>,
    },
    /// Print the systems a scene schedules, one per line.
    Systems {
        /// The scene (RON).
        #[arg(long, value_name = "PATH")]
        scene: PathBuf,
    },
    /// Grids of headless runs: plan one from a spec into a folder, run its tasks (here, or as a
    /// Slurm job array), see how far it is, merge the results.
    #[command(subcommand)]
    Sweep(SweepCommand),
}

#[derive(Subcommand, Debug)]
enum SweepCommand {
    /// Check a sweep spec (RON) and write its plan into DIR: the task list and the Slurm batch
    /// script (prints the sbatch command).
    Plan {
        /// The sweep spec.
        spec: PathBuf,
        /// The sweep's folder.
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// Run one task of the sweep in DIR (its index from SLURM_ARRAY_TASK_ID without --index);
    /// goes on from its checkpoint if it has one; does nothing if it is done.
    Task {
        /// The sweep's folder.
        dir: PathBuf,
        /// The task's index (from 0).
        #[arg(long)]
        index: Option<usize>,
    },
    /// Run every task of the sweep in DIR that has no result, here, JOBS at a time; then merge.
    Run {
        /// The sweep's folder.
        dir: PathBuf,
        /// Tasks at once.
        #[arg(long, default_value_t = 2)]
        jobs: usize,
    },
    /// Say how many tasks of the sweep in DIR are done, started, failed (and why) and waiting.
    Status {
        /// The sweep's folder.
        dir: PathBuf,
    },
    /// Merge the results of the sweep in DIR into DIR/merged.csv and DIR/merged.json, and draw
    /// the figure its spec asks for.
    Merge {
        /// The sweep's folder.
        dir: PathBuf,
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
    #[arg(long, allow_negative_numbers = true, value_parser = parse_count)]
    count: Option<usize>,
    /// Seed of the random placement (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seed)]
    seed: Option<u64>,
    /// Solver: `discrete`, `substeps=N`, `soft`, `soft=N`, `swept` or `exact` (overrides the
    /// scene).
    #[arg(long)]
    solver: Option<Solver>,
    /// Render `--frames` frames, save the window to this PNG and exit.
    #[arg(long, value_name = "PATH")]
    screenshot: Option<PathBuf>,
    /// Frames to render before `--screenshot` is taken.
    #[arg(long, default_value_t = 90, requires = "screenshot")]
    frames: u32,
    /// Open with the live panel shown (`p` shows and hides it).
    #[arg(long)]
    panel: bool,
}

#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["scene", "particles", "resume"])))]
#[command(group(clap::ArgGroup::new("length").required(true).args(["seconds", "steps"])))]
struct RunArgs {
    /// Scene file (RON).
    #[arg(long, value_name = "PATH")]
    scene: Option<PathBuf>,
    /// Particle file: `N`, then `rx ry vx vy radius mass r g b` per line, in the unit square.
    #[arg(long, value_name = "PATH")]
    particles: Option<PathBuf>,
    /// Solver: `discrete`, `substeps=N`, `soft`, `soft=N`, `swept`, `exact`, or `auto` (the
    /// cheapest that meets `--tolerance`, from a short calibration run). Default: the scene's,
    /// or `discrete`.
    #[arg(long)]
    solver: Option<SolverChoice>,
    /// With `--solver auto`: the largest acceptable error, as the larger of the position error
    /// against `exact` after a short calibration and the deepest overlap, both in radii.
    #[arg(long, allow_negative_numbers = true)]
    tolerance: Option<f64>,
    /// Boundary of a particle file's unit square: `walls`, `periodic` or `open`.
    #[arg(long)]
    boundary: Option<Boundary>,
    /// Fixed step in seconds, e.g. `0.01` or `1/60` (default: the scene's, or 1/60).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_dt)]
    dt: Option<f64>,
    /// Simulated seconds to run (rounded up to whole steps).
    #[arg(long, allow_negative_numbers = true)]
    seconds: Option<f64>,
    /// Fixed steps to run (from 1 to 10^10).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_steps)]
    steps: Option<u64>,
    /// Seed of the random placement (overrides the scene).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_seed)]
    seed: Option<u64>,
    /// Where a scene's circles are spawned (overrides the scene): `random`; `lattice` (a
    /// triangular lattice of equal circles, up to area fraction ~0.88); or `pack` (any radii,
    /// compressed under the event engine, up to ~0.85, or ~0.88 for equal circles).
    #[arg(long)]
    placement: Option<Placement>,
    /// Fill this area fraction with a scene's circles (overrides the scene's count).
    #[arg(long, value_name = "PHI", allow_negative_numbers = true)]
    area_fraction: Option<f64>,
    /// Write the report (JSON) here.
    #[arg(long, value_name = "PATH.json")]
    report: Option<PathBuf>,
    /// Write the final state here, in the particle format.
    #[arg(long, value_name = "PATH.txt")]
    dump: Option<PathBuf>,
    /// Threads for the parallel parts of a step (default: one per core). Results do not depend
    /// on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=i64::from(MAX_THREADS)))]
    threads: Option<u16>,
    /// Whether the kernels (`soft`'s contact passes, `exact`'s pair times) may use the
    /// processor's vector instructions (AVX2) where it has them. Results do not depend on it:
    /// `off` is there to show that.
    #[arg(long, value_name = "on|off", default_value = "on", value_parser = ["on", "off"])]
    vector: String,
    /// Write a checkpoint (the whole state, to go on from with `--resume`) here: at the end,
    /// when interrupted, and every `--every` steps.
    #[arg(long, value_name = "PATH")]
    checkpoint: Option<PathBuf>,
    /// Steps between checkpoints (at least 1), counted from the start of the run.
    #[arg(long, value_name = "N", requires = "checkpoint", value_parser = clap::value_parser!(u64).range(1..))]
    every: Option<u64>,
    /// Go on from a checkpoint, with its settings, for `--steps` / `--seconds` more; the result
    /// is bit for bit that of the run without the pause.
    #[arg(long, value_name = "PATH", conflicts_with_all = ["solver", "dt", "seed", "boundary", "tolerance", "placement", "area_fraction"])]
    resume: Option<PathBuf>,
}

/// A whole number from `lo` to `hi`, or the rule it breaks.
fn whole(s: &str, lo: u64, hi: u64) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(n) if (lo..=hi).contains(&n) => Ok(n),
        _ => Err(format!("must be a whole number from {lo} to {hi}, got {s}")),
    }
}

/// A seed: any whole number that fits in 64 bits.
fn parse_seed(s: &str) -> Result<u64, String> {
    whole(s, 0, u64::MAX)
}

/// A number of steps, within [`MAX_STEPS`].
fn parse_steps(s: &str) -> Result<u64, String> {
    whole(s, 1, MAX_STEPS)
}

/// A number of circles (the scene's checks bound it further).
fn parse_count(s: &str) -> Result<usize, String> {
    whole(s, 0, usize::MAX as u64).map(|n| n as usize)
}

/// A step in seconds, as a number or a fraction (`1/60`), within [`DT_RANGE`].
fn parse_dt(s: &str) -> Result<f64, String> {
    let number = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| format!("`{s}` is not a number or fraction"))
    };
    let value = match s.split_once('/') {
        Some((a, b)) => number(a)? / number(b)?,
        None => number(s)?,
    };
    let (lo, hi) = DT_RANGE;
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(format!("must be between {lo} and {hi} seconds, got {s}"))
    }
}

impl TryFrom<RunArgs> for RunOptions {
    type Error = anyhow::Error;

    fn try_from(args: RunArgs) -> anyhow::Result<Self> {
        let input = match (args.scene, args.particles) {
            (Some(_), _) if args.boundary.is_some() => bail!(
                "--boundary applies to --particles files; a scene sets its own `arena.boundary`"
            ),
            (Some(scene), _) => Input::Scene(scene),
            (None, Some(_))
                if args.placement.is_some()
                    || args.area_fraction.is_some()
                    || args.seed.is_some() =>
            {
                bail!(
                    "--placement, --area-fraction and --seed spawn a scene's circles; a particle \
                     file lists its own"
                )
            }
            (None, Some(file)) => Input::Particles(file, args.boundary),
            (None, None) => match args.resume {
                Some(checkpoint) => Input::Resume(checkpoint),
                None => unreachable!("clap requires --scene, --particles or --resume"),
            },
        };
        let length = match (args.steps, args.seconds) {
            (Some(steps), _) => Length::Steps(steps),
            (None, Some(seconds)) => Length::Seconds(seconds),
            (None, None) => unreachable!("clap requires --seconds or --steps"),
        };
        Ok(RunOptions {
            input,
            solver: args.solver,
            tolerance: args.tolerance,
            dt: args.dt,
            length,
            seed: args.seed,
            placement: args.placement,
            area_fraction: args.area_fraction,
            report: args.report,
            dump: args.dump,
            threads: args.threads,
            vector: args.vector == "on",
            checkpoint: args.checkpoint,
            every: args.every,
        })
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Some(Command::Run(args)) => RunOptions::try_from(*args)
            .and_then(cli::run::run)
            .map(|finished| finished.exit_code()),
        Some(Command::Systems { scene }) => cli::systems::systems(&scene).map(|()| 0),
        Some(Command::Sweep(command)) => match command {
            SweepCommand::Plan { spec, out } => cli::sweep::plan(&spec, &out).map(|()| 0),
            SweepCommand::Task { dir, index } => {
                cli::sweep::task(&dir, index).map(|finished| finished.exit_code())
            }
            SweepCommand::Run { dir, jobs } => cli::sweep::run(&dir, jobs).map(|()| 0),
            SweepCommand::Status { dir } => cli::sweep::status(&dir).map(|()| 0),
            SweepCommand::Merge { dir } => cli::sweep::merge(&dir).map(|()| 0),
        },
        Some(Command::Accuracy {
            out,
            scenes,
            quick,
            jobs,
        }) => {
            let jobs = jobs.unwrap_or_else(cores);
            cli::accuracy::accuracy(&out, &scenes, quick, jobs).map(|()| 0)
        }
        Some(Command::Eos {
            out,
            n,
            area_fractions,
            equilibrate,
            blocks,
            block,
            seed,
            jobs,
        }) => {
            let options = moving_circles::tools::eos::EosOptions {
                n,
                area_fractions: area_fractions
                    .unwrap_or_else(|| moving_circles::tools::eos::DEFAULT_AREA_FRACTIONS.to_vec()),
                equilibrate,
                blocks,
                block,
                seed,
            };
            let jobs = jobs.unwrap_or_else(cores);
            cli::eos::eos(&options, &out, jobs).map(|()| 0)
        }
        None => open_app(cli.app).map(|()| 0),
    };
    match result {
        Ok(code) => ExitCode::from(code),
        Err(e) => {
            eprintln!("moving_circles: {}", printable(&format!("{e:#}")));
            ExitCode::FAILURE
        }
    }
}

#[cfg(feature = "render")]
fn open_app(args: AppArgs) -> anyhow::Result<()> {
    let options = cli::app::AppOptions {
        scene: args.scene,
        count: args.count,
        seed: args.seed,
        solver: args.solver,
        screenshot: args.screenshot.map(|path| (path, args.frames)),
        panel: args.panel,
    };
    if !cli::app::open(options)? {
        bail!("the app ended with an error");
    }
    Ok(())
}

#[cfg(not(feature = "render"))]
fn open_app(_: AppArgs) -> anyhow::Result<()> {
    bail!(
        "built without the `render` feature, so there is no window; use `moving_circles run` \
         or rebuild with default features"
    )
}

/// This machine's cores: `--jobs` when not given.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}
