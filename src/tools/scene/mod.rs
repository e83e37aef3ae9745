//! Input files: scenes (RON: arena, boundary, effects, solver, spawn rules, explicit circles)
//! and the plain-text particle format, each read into a checked [`CirclesConfig`] so a bad file
//! fails with a message naming the file, the line or field, and the problem.
//!
//! - [`schema`]: what a scene file may say, and parsing it;
//! - [`check`]: checking it into a configuration;
//! - [`particles`]: the particle format, read and written exactly;
//! - [`asset`]: scenes as Bevy assets, applied again when the file changes (hot reload).
//!
//! ```ron
//! (
//!     name: "gravity",
//!     arena: (size: (16.0, 9.0), boundary: walls),
//!     effects: (gravity: (0.0, -9.81), restitution: 0.9, wall_restitution: 0.8),
//!     solver: "substeps=4",
//!     spawn: (count: 200, radius: (0.1, 0.25), speed: (0.0, 2.0), seed: 7),
//!     circles: [(position: (0.0, 3.0), velocity: (5.0, 0.0), radius: 0.5, mass: 10.0)],
//! )
//! ```

pub mod asset;
pub mod check;
pub mod particles;
pub mod schema;

pub use schema::{ArenaSpec, CircleSpec, Scene};

use crate::base::config::CirclesConfig;

/// The built-in default scene, `assets/scenes/classic.ron` (the course exercise), compiled in so
/// the app opens on it from any directory.
pub fn classic() -> CirclesConfig {
    const ORIGIN: &str = "assets/scenes/classic.ron";
    Scene::parse(include_str!("../../../assets/scenes/classic.ron"), ORIGIN)
        .and_then(|scene| scene.to_config(ORIGIN))
        .expect("the built-in classic scene is valid (tested)")
}
