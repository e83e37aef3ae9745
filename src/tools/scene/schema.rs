//! The scene file's schema: the RON a scene is written in ([`Scene`], [`ArenaSpec`],
//! [`CircleSpec`], segment walls as polylines), every field with a default so a file names only what it changes, and
//! [`Scene::parse`], which reads the text and names the line and column of a syntax error or an
//! unknown field. Checking the values is `check`'s job.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use crate::base::arena::Boundary;
use crate::base::config::{DropConfig, Effects, MassModel, SoftConfig, Solver, SpawnConfig};
use crate::base::error::InputError;
use crate::tools::io::{BYTE_ORDER_MARK, BYTE_ORDER_MARK_MESSAGE};

/// The arena as a scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArenaSpec {
    /// Width and height.
    pub size: DVec2,
    /// Centre.
    pub center: DVec2,
    /// `walls`, `periodic` or `open` (no edges).
    pub boundary: Boundary,
}

impl Default for ArenaSpec {
    fn default() -> Self {
        Self {
            size: DVec2::new(16.0, 9.0),
            center: DVec2::ZERO,
            boundary: Boundary::Walls,
        }
    }
}

/// One circle placed exactly.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Centre.
    pub position: DVec2,
    /// Velocity (default: at rest).
    #[serde(default)]
    pub velocity: DVec2,
    /// Angular velocity in radians per second, counter-clockwise (default: not turning).
    #[serde(default)]
    pub angular_velocity: f64,
    /// Radius.
    pub radius: f64,
    /// Mass; by default from the scene's mass model.
    #[serde(default)]
    pub mass: Option<f64>,
    /// Colour as sRGB bytes; by default light grey.
    #[serde(default)]
    pub color: Option<[u8; 3]>,
    /// A static obstacle (a peg): infinite mass ([`Mass::IMMOVABLE`](crate::base::components::Mass)),
    /// at rest for good. Gives no `mass` and no `velocity` (a moving immovable circle is a
    /// kinematic one, which code steers).
    #[serde(default)]
    pub immovable: bool,
}

/// A scene file. Every field has a default, so a file names only what it changes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    /// Short name.
    pub name: String,
    /// What the scene shows.
    pub description: String,
    /// Size, centre and boundary.
    pub arena: ArenaSpec,
    /// Effects and their parameters (the boundary is the arena's).
    pub effects: Effects,
    /// How masses are assigned where a circle does not give its own.
    pub mass: MassModel,
    /// How a step is advanced.
    pub solver: Solver,
    /// How the `soft` solver's contacts behave.
    pub soft: SoftConfig,
    /// Fixed step in seconds.
    pub dt: f64,
    /// Random circles, if any.
    pub spawn: Option<SpawnConfig>,
    /// Circles placed exactly.
    pub circles: Vec<CircleSpec>,
    /// Circles dropped in one at a time while it runs, if any.
    pub drop: Option<DropConfig>,
    /// Segment walls, as polylines: each is a list of two or more points inside the arena,
    /// joined in order (two points: one segment). Not on a periodic arena.
    pub segments: Vec<Vec<DVec2>>,
    /// Push apart explicit circles that overlap instead of rejecting the scene.
    pub separate_overlaps: bool,
}

impl Default for Scene {
    fn default() -> Self {
        Self {
            name: String::new(),
            description: String::new(),
            arena: ArenaSpec::default(),
            effects: Effects::default(),
            mass: MassModel::default(),
            solver: Solver::default(),
            soft: SoftConfig::default(),
            dt: 1.0 / 60.0,
            spawn: None,
            circles: Vec::new(),
            segments: Vec::new(),
            drop: None,
            separate_overlaps: false,
        }
    }
}

impl Scene {
    /// Reads a scene from RON text. `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, InputError> {
        if text.starts_with(BYTE_ORDER_MARK) {
            return Err(InputError::line(origin, 1, BYTE_ORDER_MARK_MESSAGE));
        }
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        options.from_str::<Scene>(text).map_err(|e| {
            let mut message = e.code.to_string();
            if let ron::error::Error::NoSuchStructField { found, .. } = &e.code
                && let Some(home) = home_of(found)
            {
                message.push_str(&format!("; `{found}` belongs to {home}"));
            }
            InputError {
                origin: origin.to_owned(),
                location: Some(format!(
                    "line {}, column {}",
                    e.span.start.line, e.span.start.col
                )),
                message,
            }
        })
    }
}

/// Where a field given in the wrong place of a scene belongs, for the fields that are easy to
/// put in the wrong place: what the error adds to RON's list of the fields that fit there (the
/// field is unknown where it stands, so that is never its home).
fn home_of(field: &str) -> Option<&'static str> {
    Some(match field {
        "boundary" => "the arena: `arena: (boundary: periodic)`",
        "gravity" | "restitution" | "drag" | "friction" => {
            "the effects: `effects: (gravity: (0.0, -9.81))`"
        }
        "solver" | "dt" | "mass" => "the scene's top level: `(solver: \"exact\", dt: 0.01, ...)`",
        _ => return None,
    })
}
