//! The `moving_circles` binary: opens the app (feature `render`) with the seed's scene, or a
//! configured one.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use moving_circles::prelude::*;

/// Moving, colliding circles. Without a subcommand, opens the app.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    /// Number of circles to spawn.
    #[arg(long)]
    count: Option<usize>,
    /// Seed of the random placement.
    #[arg(long)]
    seed: Option<u64>,
    /// Solver: `discrete` or `substeps=N`.
    #[arg(long)]
    solver: Option<Solver>,
    /// Render `--frames` frames, save the window to this PNG and exit.
    #[arg(long, value_name = "PATH")]
    screenshot: Option<PathBuf>,
    /// Frames to render before `--screenshot` is taken.
    #[arg(long, default_value_t = 90, requires = "screenshot")]
    frames: u32,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let mut config = CirclesConfig::default();
    if let Some(count) = cli.count {
        config.spawn.count = count;
    }
    if let Some(seed) = cli.seed {
        config.spawn.seed = seed;
    }
    if let Some(solver) = cli.solver {
        config.solver = solver;
    }
    open_app(config, cli.screenshot.map(|path| (path, cli.frames)))
}

#[cfg(feature = "render")]
fn open_app(config: CirclesConfig, screenshot: Option<(PathBuf, u32)>) -> ExitCode {
    use moving_circles::render::{self, NO_WINDOW_HINT};

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
    let exit = render::app(config, screenshot).run();
    if exit.is_success() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

#[cfg(not(feature = "render"))]
fn open_app(_: CirclesConfig, _: Option<(PathBuf, u32)>) -> ExitCode {
    eprintln!(
        "moving_circles was built without the `render` feature, so it has no window; \
         rebuild with default features"
    );
    ExitCode::FAILURE
}
