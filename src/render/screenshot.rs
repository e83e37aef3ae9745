//! `--screenshot PATH --frames N`: render N frames, save the window to a PNG (written
//! atomically, so a half-written picture never appears) and exit, so the app can be checked
//! without a person.

use std::path::PathBuf;

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

use crate::tools::io::write_atomically;

/// Takes one screenshot after `frames` frames, then exits (with an error code if saving failed).
#[derive(Clone, Debug)]
pub struct ScreenshotPlugin {
    /// Where the PNG goes.
    pub path: PathBuf,
    /// Frames to render first.
    pub frames: u32,
}

#[derive(Resource, Clone, Debug)]
struct ScreenshotPlan {
    path: PathBuf,
    frames: u32,
}

impl Plugin for ScreenshotPlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(ScreenshotPlan {
            path: self.path.clone(),
            frames: self.frames,
        })
        .add_systems(Update, take_screenshot);
    }
}

fn take_screenshot(mut commands: Commands, plan: Res<ScreenshotPlan>, mut frame: Local<u32>) {
    *frame += 1;
    if *frame != plan.frames.max(1) {
        return;
    }
    let path = plan.path.clone();
    commands.spawn(Screenshot::primary_window()).observe(
        move |captured: On<ScreenshotCaptured>, mut exit: MessageWriter<AppExit>| match save_png(
            &captured.image,
            &path,
        ) {
            Ok(()) => {
                info!("screenshot saved to {}", path.display());
                exit.write(AppExit::Success);
            }
            Err(e) => {
                error!("cannot save screenshot to {}: {e}", path.display());
                exit.write(AppExit::error());
            }
        },
    );
}

fn save_png(image: &Image, path: &std::path::Path) -> Result<(), String> {
    let rgb = image
        .clone()
        .try_into_dynamic()
        .map_err(|e| e.to_string())?
        .to_rgb8();
    let mut png = std::io::Cursor::new(Vec::new());
    rgb.write_to(&mut png, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    write_atomically(path, png.get_ref()).map_err(|e| e.to_string())
}
