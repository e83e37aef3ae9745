//! The windowed app as the command line opens it (feature `render`): the scene (or the built-in
//! `classic`) with the command line's overrides, a clear message instead of a crash where no
//! window can open, and the exit status.

use std::path::PathBuf;

use crate::base::config::{CirclesConfig, Solver};
use crate::base::error::printable;
use crate::render::{self, NO_WINDOW_HINT};
use crate::tools::scene::{Scene, classic};

/// What the app is opened on.
#[derive(Clone, Debug, Default)]
pub struct AppOptions {
    /// Scene file, watched for changes; the built-in `classic` scene if `None`.
    pub scene: Option<PathBuf>,
    /// Number of random circles (overrides the scene).
    pub count: Option<usize>,
    /// Seed of the random placement (overrides the scene).
    pub seed: Option<u64>,
    /// Solver (overrides the scene).
    pub solver: Option<Solver>,
    /// Render this many frames, save a PNG there and exit.
    pub screenshot: Option<(PathBuf, u32)>,
    /// Whether the live panel starts shown.
    pub panel: bool,
}

/// The configuration the app opens on.
pub fn app_config(options: &AppOptions) -> anyhow::Result<CirclesConfig> {
    let mut config = match &options.scene {
        Some(path) => Scene::load(path)?,
        None => classic(),
    };
    if let Some(count) = options.count {
        config.spawn.count = count;
        config.spawn.area_fraction = None;
    }
    if let Some(seed) = options.seed {
        config.spawn.seed = seed;
    }
    if let Some(solver) = options.solver {
        config.solver = solver;
    }
    // The overrides go through the same check as the file did (`--count` past the limit).
    config.check()?;
    Ok(config)
}

/// Opens the window and runs until it closes; whether the app ended well.
pub fn open(options: AppOptions) -> anyhow::Result<bool> {
    let config = app_config(&options)?;
    if let Some(problem) = render::display_problem() {
        anyhow::bail!("{problem}");
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
        eprintln!(
            "moving_circles: the app stopped: {}{location}\n\n{NO_WINDOW_HINT}",
            printable(message)
        );
    }));
    let options = render::AppOptions {
        scene_file: options.scene,
        screenshot: options.screenshot,
        panel: options.panel,
    };
    Ok(render::app(config, options).run().is_success())
}
