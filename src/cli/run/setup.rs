//! Before `run` steps: the configuration of its input with the command line's overrides, the
//! solver (`auto` chosen by measurement), the number of steps, the threads, the outputs checked
//! up front, and the headless app with its circles placed.

use anyhow::{Context, bail};
use bevy::prelude::App;

use super::options::{Input, Length, MAX_STEPS, RunOptions, SolverChoice};
use crate::base::config::{CirclesConfig, Placement, Solver};
use crate::base::error::InputError;
use crate::game::spawn::SpawnReport;
use crate::step::schedule::StopRequest;
use crate::tools::accuracy::auto::choose_solver;
use crate::tools::io::{check_output_path, same_output};
use crate::tools::run::headless_app_with;
use crate::tools::scene::{Scene, particles};

/// Circles above which `run` says it is placing them before it starts (placing millions takes
/// seconds to minutes).
const ANNOUNCE_SPAWN_FROM: usize = 1_000_000;
/// The same for a `pack` placement, whose compression takes about a second per 5000 circles.
const ANNOUNCE_PACK_FROM: usize = 20_000;
/// The same for a random placement asked for at most this many tries in all (circles times
/// `attempts_per_circle`): about 6 s when the arena is too full for most of them, since each
/// circle that fits nowhere is tried every time (17 M tries a second, release build).
const ANNOUNCE_TRIES_FROM: u64 = 100_000_000;

/// The configuration of a scene or particle file with the command line's overrides, checked,
/// and the report's name for it.
pub(super) fn configure(
    input: &Input,
    options: &RunOptions,
    stop: impl Fn() -> bool,
) -> anyhow::Result<(CirclesConfig, String)> {
    let (mut config, source) = load(input, stop)?;
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
    config
        .check()
        .map_err(|e| InputError::from_field(&source, e))?;
    if options.seed.is_some() && config.spawn.target_count(&config.arena) == 0 {
        bail!("--seed places a scene's random circles, and {source} has none (`spawn.count` 0)");
    }
    config.solver = choose(&config, options.solver, options.tolerance)?;
    Ok((config, source))
}

/// The steps `length` asks for at `dt`, within [`MAX_STEPS`].
pub(super) fn steps_of(length: Length, dt: f64) -> anyhow::Result<u64> {
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

pub(crate) fn set_threads(threads: Option<u16>) {
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
/// takes a while, and afterwards when not all fit); `None` if `stop` was raised while placing
/// or spawning them.
pub(super) fn start(
    config: CirclesConfig,
    source: &str,
    stop: StopRequest,
) -> anyhow::Result<Option<App>> {
    let placing = config.spawn.target_count(&config.arena);
    let how = match config.spawn.placement {
        Placement::Pack => "compressing",
        Placement::Lattice => "placing on a lattice",
        Placement::Random => "placing at random",
    };
    let tries = placing as u64 * u64::from(config.spawn.attempts_per_circle);
    let announce = match config.spawn.placement {
        Placement::Pack => placing >= ANNOUNCE_PACK_FROM,
        Placement::Lattice => placing >= ANNOUNCE_SPAWN_FROM,
        Placement::Random => placing >= ANNOUNCE_SPAWN_FROM || tries >= ANNOUNCE_TRIES_FROM,
    };
    if announce {
        eprintln!("moving_circles: {how} {placing} circles (this takes a while)");
    }
    let asked = stop.clone();
    let app = headless_app_with(config, |app| {
        app.insert_resource(stop);
    });
    let spawn = app.world().resource::<SpawnReport>();
    if spawn.interrupted || asked.raised() {
        // Raised while the circles were placed, or spawned (a second for millions): nothing
        // was run, and the process exits next, so the system takes the world's memory back.
        std::mem::forget(app);
        return Ok(None);
    }
    if let Some(refused) = &spawn.refused {
        bail!("{source}: cannot spawn the scene's circles: {refused}");
    }
    if spawn.placed < spawn.requested {
        eprintln!(
            "moving_circles: warning: placed {} of {} circles; the arena has no room for more",
            spawn.placed, spawn.requested
        );
    }
    Ok(Some(app))
}

/// Refuses, before any work, outputs that could not be written or would clobber something:
/// paths that are not regular files (devices, directories, links), missing folders, names too
/// long for the temporary file, two outputs on one file, and an output on the run's input.
pub(super) fn check_outputs(options: &RunOptions) -> anyhow::Result<()> {
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

/// The configuration and the report's name for `input`; a particle file's reading asks
/// `stop` before each line whether to give up.
pub(super) fn load(
    input: &Input,
    stop: impl Fn() -> bool,
) -> anyhow::Result<(CirclesConfig, String)> {
    Ok(match input {
        Input::Scene(path) => (Scene::load(path)?, path.display().to_string()),
        Input::Particles(path, boundary) => {
            let boundary = boundary.unwrap_or_default();
            let circles = particles::read_until(path, boundary, stop)?;
            (
                particles::to_config(circles, boundary),
                path.display().to_string(),
            )
        }
        Input::Resume(_) => unreachable!("a checkpoint is resumed, not loaded as a scene"),
    })
}

/// The solver to run: the scene's, the one asked for, or the cheapest within `tolerance`.
pub(super) fn choose(
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
