//! A game's first afternoon: Bevy's `DefaultPlugins`, `CirclesPlugins::default()` (which
//! spawns nothing and brings no camera, keys or HUD), a camera of the game's own and two circles
//! drawn with the game's own meshes. Their `Transform`s follow the simulation, interpolated
//! between fixed steps, so they move smoothly at any frame rate.
//!
//! `cargo run --example own_sprites` opens the window;
//! `cargo run --example own_sprites -- --screenshot own.png --frames 60` saves the 60th frame
//! and exits.

use std::path::PathBuf;

use bevy::camera::ScalingMode;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::render::screenshot::ScreenshotPlugin;

fn main() -> AppExit {
    let mut app = App::new();
    app.add_plugins((DefaultPlugins, CirclesPlugins::default()))
        .add_systems(Startup, setup);
    match screenshot(std::env::args().skip(1)) {
        Ok(Some((path, frames))) => {
            app.add_plugins(ScreenshotPlugin { path, frames });
        }
        Ok(None) => {}
        Err(message) => {
            eprintln!("own_sprites: {message}\nusage: own_sprites [--screenshot PATH --frames N]");
            return AppExit::error();
        }
    }
    app.run()
}

/// A camera that shows the default arena (16 × 9, walls, centred on the origin) and two
/// circles, each a mesh of the game's own.
fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<ColorMaterial>>,
) {
    commands.spawn((
        Camera2d,
        Projection::Orthographic(OrthographicProjection {
            scaling_mode: ScalingMode::AutoMin {
                min_width: 16.0,
                min_height: 9.0,
            },
            ..OrthographicProjection::default_2d()
        }),
    ));
    let circles = [
        (
            0.8,
            DVec2::new(-4.0, 1.0),
            DVec2::new(3.0, 1.5),
            Color::srgb(0.95, 0.45, 0.2),
        ),
        (
            0.5,
            DVec2::new(3.0, -2.0),
            DVec2::new(-2.0, 2.5),
            Color::srgb(0.2, 0.6, 0.95),
        ),
    ];
    for (radius, position, velocity, color) in circles {
        commands.spawn((
            Radius(radius),
            Position(position),
            Velocity(velocity),
            Mesh2d(meshes.add(Circle::new(radius as f32))),
            MeshMaterial2d(materials.add(color)),
        ));
    }
}

/// `--screenshot PATH --frames N`, if given.
fn screenshot(mut args: impl Iterator<Item = String>) -> Result<Option<(PathBuf, u32)>, String> {
    let (mut path, mut frames) = (None, 60);
    while let Some(arg) = args.next() {
        let value = args.next().ok_or(format!("{arg} needs a value"))?;
        match arg.as_str() {
            "--screenshot" => path = Some(PathBuf::from(value)),
            "--frames" => {
                frames = value
                    .parse()
                    .map_err(|_| format!("--frames takes a whole number, got {value:?}"))?;
            }
            _ => return Err(format!("unknown argument {arg:?}")),
        }
    }
    Ok(path.map(|path| (path, frames)))
}
