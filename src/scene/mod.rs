//! Scene files: a RON description of what to simulate (arena, boundary, effects, solver, spawn
//! rules, explicit circles), read into a [`CirclesConfig`] after checking every field, so a bad
//! file fails with a message naming the file, the line or field, and the problem.
//!
//! Also the plain-text particle format ([`particles`]) and the asset loader with hot reload
//! ([`asset`]).
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
pub mod particles;

use std::fmt;
use std::path::Path;

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::Deserialize;

use crate::config::{Arena, Boundary, CirclesConfig, Effects, MassModel, Solver, SpawnConfig};
use crate::spawn::CircleInit;

/// A problem with an input file, located as precisely as the input allows.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputError {
    /// The file (or other origin) the input came from.
    pub origin: String,
    /// Where in it: `line 12`, `line 3, column 7` or `field circles[2].radius`.
    pub location: Option<String>,
    /// What is wrong.
    pub message: String,
}

impl InputError {
    /// An error at a named field of the input.
    pub fn field(origin: &str, field: impl fmt::Display, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: Some(format!("field `{field}`")),
            message: message.into(),
        }
    }

    /// An error at a line of the input.
    pub fn line(origin: &str, line: usize, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: Some(format!("line {line}")),
            message: message.into(),
        }
    }

    /// An error about the input as a whole.
    pub fn whole(origin: &str, message: impl Into<String>) -> Self {
        Self {
            origin: origin.to_owned(),
            location: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(at) => write!(f, "{}: {at}: {}", self.origin, self.message),
            None => write!(f, "{}: {}", self.origin, self.message),
        }
    }
}

impl std::error::Error for InputError {}

/// The arena as a scene file gives it.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArenaSpec {
    /// Width and height.
    pub size: DVec2,
    /// Centre.
    pub center: DVec2,
    /// `walls` or `periodic`.
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
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Centre.
    pub position: DVec2,
    /// Velocity (default: at rest).
    #[serde(default)]
    pub velocity: DVec2,
    /// Radius.
    pub radius: f64,
    /// Mass; by default from the scene's mass model.
    #[serde(default)]
    pub mass: Option<f64>,
    /// Colour as sRGB bytes; by default light grey.
    #[serde(default)]
    pub color: Option<[u8; 3]>,
}

/// A scene file. Every field has a default, so a file names only what it changes.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Scene {
    /// Short name.
    pub name: String,
    /// What the scene shows.
    pub description: String,
    /// Size, centre and boundary.
    pub arena: ArenaSpec,
    /// Effects and their parameters (the boundary comes from `arena`).
    pub effects: Effects,
    /// How masses are assigned where a circle does not give its own.
    pub mass: MassModel,
    /// How a step is advanced.
    pub solver: Solver,
    /// Fixed step in seconds.
    pub dt: f64,
    /// Random circles, if any.
    pub spawn: Option<SpawnConfig>,
    /// Circles placed exactly.
    pub circles: Vec<CircleSpec>,
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
            dt: 1.0 / 60.0,
            spawn: None,
            circles: Vec::new(),
            separate_overlaps: false,
        }
    }
}

/// The built-in default scene, `assets/scenes/classic.ron` (the course exercise), compiled in so
/// the app opens on it from any directory.
pub fn classic() -> CirclesConfig {
    const ORIGIN: &str = "assets/scenes/classic.ron";
    Scene::parse(include_str!("../../assets/scenes/classic.ron"), ORIGIN)
        .and_then(|scene| scene.to_config(ORIGIN))
        .expect("the built-in classic scene is valid (tested)")
}

/// Smallest and largest accepted step: below 1 ns the fixed clock (nanoseconds) cannot
/// represent it; above a minute nothing sensible is being simulated.
pub const DT_RANGE: (f64, f64) = (1e-9, 60.0);
/// Most random circles a scene may ask for (bounds memory before anything is allocated).
pub const MAX_SPAWN: usize = 20_000_000;

impl Scene {
    /// Reads a scene from RON text. `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, InputError> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        options.from_str::<Scene>(text).map_err(|e| InputError {
            origin: origin.to_owned(),
            location: Some(format!(
                "line {}, column {}",
                e.span.start.line, e.span.start.col
            )),
            message: e.code.to_string(),
        })
    }

    /// Reads and checks a scene file into a configuration.
    pub fn load(path: &Path) -> Result<CirclesConfig, InputError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::whole(&origin, format!("cannot read: {e}")))?;
        Self::parse(&text, &origin)?.to_config(&origin)
    }

    /// Checks every field and builds the configuration. `origin` names the file in errors.
    pub fn to_config(&self, origin: &str) -> Result<CirclesConfig, InputError> {
        let err = |field: &str, message: String| InputError::field(origin, field, message);
        let (dt_min, dt_max) = DT_RANGE;
        if !(self.dt.is_finite() && self.dt >= dt_min && self.dt <= dt_max) {
            return Err(err(
                "dt",
                format!(
                    "must be between {dt_min} and {dt_max} seconds, got {}",
                    self.dt
                ),
            ));
        }
        let size = self.arena.size;
        if !(size.is_finite() && size.x > 0.0 && size.y > 0.0) {
            return Err(err(
                "arena.size",
                format!("must be two positive finite numbers, got {size}"),
            ));
        }
        if !self.arena.center.is_finite() {
            return Err(err(
                "arena.center",
                format!("must be finite, got {}", self.arena.center),
            ));
        }
        let arena = Arena {
            min: self.arena.center - size / 2.0,
            max: self.arena.center + size / 2.0,
        };
        let effects = Effects {
            boundary: self.arena.boundary,
            ..self.effects
        };
        check_effects(&effects).map_err(|(field, message)| err(field, message))?;
        check_mass_model(self.mass).map_err(|message| err("mass", message))?;

        let spawn = match &self.spawn {
            Some(spawn) => {
                check_spawn(spawn, &arena)
                    .map_err(|(field, message)| err(&format!("spawn.{field}"), message))?;
                SpawnConfig {
                    mass: self.mass,
                    ..spawn.clone()
                }
            }
            None => SpawnConfig {
                count: 0,
                mass: self.mass,
                ..SpawnConfig::default()
            },
        };

        let mut circles = Vec::with_capacity(self.circles.len());
        for (i, spec) in self.circles.iter().enumerate() {
            let circle = CircleInit {
                position: spec.position,
                velocity: spec.velocity,
                radius: spec.radius,
                mass: spec.mass.unwrap_or_else(|| self.mass.mass_of(spec.radius)),
                tint: spec.color.unwrap_or([230, 230, 230]),
            };
            check_circle(&circle, &arena, effects.boundary)
                .map_err(|(field, message)| err(&format!("circles[{i}].{field}"), message))?;
            circles.push(circle);
        }
        if self.separate_overlaps {
            separate_overlaps(&mut circles, &arena, effects.boundary);
        }
        if let Some((i, j, depth)) = first_overlap(&circles, effects.boundary, &arena) {
            return Err(err(
                &format!("circles[{j}]"),
                format!(
                    "overlaps circles[{i}] by {depth:.3e} (set `separate_overlaps: true` to push them apart)"
                ),
            ));
        }
        Ok(CirclesConfig {
            arena,
            spawn,
            solver: self.solver,
            effects,
            dt: self.dt,
            circles,
        })
    }
}

fn check_effects(effects: &Effects) -> Result<(), (&'static str, String)> {
    let unit = |x: f64| x.is_finite() && (0.0..=1.0).contains(&x);
    if !unit(effects.restitution) {
        return Err((
            "effects.restitution",
            format!("must be in [0, 1], got {}", effects.restitution),
        ));
    }
    if !unit(effects.wall_restitution) {
        return Err((
            "effects.wall_restitution",
            format!("must be in [0, 1], got {}", effects.wall_restitution),
        ));
    }
    if let Some(g) = effects.gravity
        && !g.is_finite()
    {
        return Err(("effects.gravity", format!("must be finite, got {g}")));
    }
    if let Some(drag) = effects.drag
        && !(drag.is_finite() && drag >= 0.0)
    {
        return Err((
            "effects.drag",
            format!("must be a finite rate >= 0 (1/s), got {drag}"),
        ));
    }
    Ok(())
}

fn check_mass_model(mass: MassModel) -> Result<(), String> {
    match mass {
        MassModel::Area { density } if !(density.is_finite() && density > 0.0) => Err(format!(
            "Area density must be positive and finite, got {density}"
        )),
        MassModel::Equal(m) if !(m.is_finite() && m > 0.0) => {
            Err(format!("Equal mass must be positive and finite, got {m}"))
        }
        _ => Ok(()),
    }
}

fn check_spawn(spawn: &SpawnConfig, arena: &Arena) -> Result<(), (&'static str, String)> {
    let (r0, r1) = spawn.radius;
    if !(r0.is_finite() && r1.is_finite() && r0 > 0.0 && r0 <= r1) {
        return Err((
            "radius",
            format!("must be (min, max) with 0 < min <= max, got ({r0}, {r1})"),
        ));
    }
    let (s0, s1) = spawn.speed;
    if !(s0.is_finite() && s1.is_finite() && s0 >= 0.0 && s0 <= s1) {
        return Err((
            "speed",
            format!("must be (min, max) with 0 <= min <= max, got ({s0}, {s1})"),
        ));
    }
    if let Some(phi) = spawn.area_fraction
        && !(phi.is_finite() && phi > 0.0 && phi <= 0.9)
    {
        return Err((
            "area_fraction",
            format!("must be in (0, 0.9] (0.907 is the densest packing), got {phi}"),
        ));
    }
    let n = spawn.target_count(arena);
    if n > MAX_SPAWN {
        return Err((
            "count",
            format!("asks for {n} circles; at most {MAX_SPAWN} are supported"),
        ));
    }
    if spawn.attempts_per_circle == 0 {
        return Err(("attempts_per_circle", "must be at least 1".to_owned()));
    }
    Ok(())
}

/// Checks one explicit circle: finite, positive radius and mass, inside the arena, not larger
/// than it. Returns the offending field and the problem.
pub fn check_circle(
    c: &CircleInit,
    arena: &Arena,
    boundary: Boundary,
) -> Result<(), (&'static str, String)> {
    if !c.position.is_finite() {
        return Err(("position", format!("must be finite, got {}", c.position)));
    }
    if !c.velocity.is_finite() {
        return Err(("velocity", format!("must be finite, got {}", c.velocity)));
    }
    if !(c.radius.is_finite() && c.radius > 0.0) {
        return Err((
            "radius",
            format!("must be positive and finite, got {}", c.radius),
        ));
    }
    if c.mass.is_nan() || c.mass <= 0.0 {
        return Err(("mass", format!("must be positive, got {}", c.mass)));
    }
    let size = arena.size();
    if 2.0 * c.radius > size.min_element() {
        return Err((
            "radius",
            format!(
                "{} is larger than the arena ({} × {})",
                c.radius, size.x, size.y
            ),
        ));
    }
    let slack = rounding_slack(c.position, c.radius);
    let (lo, hi) = match boundary {
        Boundary::Walls => (arena.min + c.radius - slack, arena.max - c.radius + slack),
        Boundary::Periodic => (arena.min, arena.max),
    };
    if !(c.position.cmpge(lo).all() && c.position.cmple(hi).all()) {
        return Err((
            "position",
            format!(
                "({}, {}) with radius {} is not inside the arena [{}, {}] × [{}, {}]",
                c.position.x,
                c.position.y,
                c.radius,
                arena.min.x,
                arena.max.x,
                arena.min.y,
                arena.max.y
            ),
        ));
    }
    Ok(())
}

/// How much two f64 coordinates near `p` can disagree by rounding alone: a few ulps of the
/// largest magnitude involved. Touching within this is touching, not overlapping.
pub fn rounding_slack(p: DVec2, radius: f64) -> f64 {
    4.0 * f64::EPSILON * p.abs().max_element().max(radius)
}

/// The first pair of circles that overlaps by more than rounding: `(i, j, depth)`.
pub fn first_overlap(
    circles: &[CircleInit],
    boundary: Boundary,
    arena: &Arena,
) -> Option<(usize, usize, f64)> {
    let space = crate::collide::collision_space(arena, boundary);
    crate::diagnostics::overlapping_circles(circles, space)
        .into_iter()
        .find(|&(i, j, depth)| {
            let (a, b) = (&circles[i], &circles[j]);
            depth > rounding_slack(a.position, a.radius).max(rounding_slack(b.position, b.radius))
        })
}

/// Pushes overlapping circles apart (positions only, split by inverse mass, kept inside the
/// arena), for at most a bounded number of sweeps; whatever still overlaps is reported by the
/// caller's overlap check.
pub fn separate_overlaps(circles: &mut [CircleInit], arena: &Arena, boundary: Boundary) {
    use crate::collide::{ContactScratch, contact::Body, resolve_all_contacts};
    let space = crate::collide::collision_space(arena, boundary);
    let mut scratch = ContactScratch::default();
    for _ in 0..1000 {
        scratch.clear();
        for c in circles.iter() {
            scratch.push(Body {
                position: c.position,
                velocity: DVec2::ZERO, // no impulses: only positions move
                radius: c.radius,
                inv_mass: if c.mass.is_finite() {
                    1.0 / c.mass
                } else {
                    0.0
                },
            });
        }
        let stats = resolve_all_contacts(&mut scratch, space, 1.0);
        for (i, c) in circles.iter_mut().enumerate() {
            let mut p = scratch.body(i).position;
            let mut v = DVec2::ZERO;
            match boundary {
                Boundary::Walls => {
                    crate::boundary::reflect_off_walls(&mut p, &mut v, c.radius, arena, 1.0);
                }
                Boundary::Periodic => p = crate::boundary::wrap_into(p, arena),
            }
            c.position = p;
        }
        if stats.contacts == 0 {
            break;
        }
    }
}
