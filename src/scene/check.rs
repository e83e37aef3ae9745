//! Checking what an input file says before anything runs: [`Scene::to_config`] turns a parsed
//! scene into a [`CirclesConfig`] through the configuration's own checks
//! ([`CirclesConfig::check`]) plus what only a file has — explicit circles, each inside the
//! arena ([`check_circle`]) and none overlapping another beyond rounding ([`first_overlap`]).
//! Every error names the file and the field.

use std::path::Path;

use bevy::math::DVec2;

use super::schema::Scene;
use crate::arena::Arena;
use crate::circle::{CircleState, discs};
use crate::collide::overlaps::overlapping_circles;
use crate::collide::pass::separate_overlaps;
use crate::components::Tint;
use crate::config::{CirclesConfig, MIN_RADIUS_FRACTION, SpawnConfig, min_radius};
use crate::error::{FieldError, InputError};

impl Scene {
    /// Reads and checks a scene file into a configuration.
    pub fn load(path: &Path) -> Result<CirclesConfig, InputError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| InputError::whole(&origin, format!("cannot read: {e}")))?;
        Self::parse(&text, &origin)?.to_config(&origin)
    }

    /// Checks every field and builds the configuration. `origin` names the file in errors.
    ///
    /// ```
    /// use moving_circles::prelude::*;
    ///
    /// let scene = Scene::parse("(arena: (size: (4.0, 4.0), boundary: periodic))", "s.ron").unwrap();
    /// let config = scene.to_config("s.ron").unwrap();
    /// assert!(config.arena.is_periodic());
    /// let bad = Scene::parse("(dt: -1.0)", "s.ron").unwrap().to_config("s.ron").unwrap_err();
    /// assert!(bad.to_string().starts_with("s.ron: field `dt`: must be between"));
    /// ```
    pub fn to_config(&self, origin: &str) -> Result<CirclesConfig, InputError> {
        let field_error = |e: FieldError| InputError::from_field(origin, e);
        let size = self.arena.size;
        if !(size.is_finite() && size.x > 0.0 && size.y > 0.0) {
            return Err(field_error(FieldError::new(
                "arena.size",
                format!("must be two positive finite numbers, got {size}"),
            )));
        }
        if !self.arena.center.is_finite() {
            return Err(field_error(FieldError::new(
                "arena.center",
                format!("must be finite, got {}", self.arena.center),
            )));
        }
        let arena = Arena {
            min: self.arena.center - size / 2.0,
            max: self.arena.center + size / 2.0,
            boundary: self.arena.boundary,
        };
        let spawn = match &self.spawn {
            Some(spawn) => SpawnConfig {
                mass: self.mass,
                ..spawn.clone()
            },
            None => SpawnConfig {
                count: 0,
                mass: self.mass,
                ..SpawnConfig::default()
            },
        };
        let mut config = CirclesConfig {
            arena,
            spawn,
            solver: self.solver,
            effects: self.effects,
            dt: self.dt,
            circles: Vec::with_capacity(self.circles.len()),
        };
        config.check().map_err(field_error)?;
        for (i, spec) in self.circles.iter().enumerate() {
            let circle = CircleState {
                position: spec.position,
                velocity: spec.velocity,
                radius: spec.radius,
                mass: spec.mass.unwrap_or_else(|| self.mass.mass_of(spec.radius)),
                tint: spec.color.unwrap_or(Tint::default().0),
            };
            check_circle(&circle, &arena)
                .map_err(|e| field_error(e.within(&format!("circles[{i}]"))))?;
            config.circles.push(circle);
        }
        if self.separate_overlaps {
            separate_overlaps(&mut config.circles, &arena);
        }
        if let Some((i, j, depth)) = first_overlap(&config.circles, &arena) {
            return Err(field_error(FieldError::new(
                format!("circles[{j}]"),
                format!(
                    "overlaps circles[{i}] by {depth:.3e} (set `separate_overlaps: true` to push them apart)"
                ),
            )));
        }
        Ok(config)
    }
}

/// Checks one explicit circle: finite, positive radius and mass, inside the arena (entirely,
/// with walls; its centre, when periodic), not larger than it.
pub fn check_circle(c: &CircleState, arena: &Arena) -> Result<(), FieldError> {
    if !c.position.is_finite() {
        return Err(FieldError::new(
            "position",
            format!("must be finite, got {}", c.position),
        ));
    }
    if !c.velocity.is_finite() {
        return Err(FieldError::new(
            "velocity",
            format!("must be finite, got {}", c.velocity),
        ));
    }
    if !(c.radius.is_finite() && c.radius > 0.0) {
        return Err(FieldError::new(
            "radius",
            format!("must be positive and finite, got {}", c.radius),
        ));
    }
    if c.mass.is_nan() || c.mass <= 0.0 {
        return Err(FieldError::new(
            "mass",
            format!("must be positive, got {}", c.mass),
        ));
    }
    if c.radius < min_radius(arena) {
        return Err(FieldError::new(
            "radius",
            // `{:?}` writes extreme magnitudes with an exponent instead of 300 digits.
            format!(
                "{:?} is below {MIN_RADIUS_FRACTION:?} of the arena's smaller side ({:?})",
                c.radius,
                min_radius(arena)
            ),
        ));
    }
    let size = arena.size();
    if 2.0 * c.radius > size.min_element() {
        return Err(FieldError::new(
            "radius",
            format!(
                "{} is larger than the arena ({} × {})",
                c.radius, size.x, size.y
            ),
        ));
    }
    let slack = rounding_slack(c.position, c.radius);
    let (lo, hi) = if arena.is_periodic() {
        (arena.min, arena.max)
    } else {
        (arena.min + c.radius - slack, arena.max - c.radius + slack)
    };
    if !(c.position.cmpge(lo).all() && c.position.cmple(hi).all()) {
        return Err(FieldError::new(
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
pub fn first_overlap(circles: &[CircleState], arena: &Arena) -> Option<(usize, usize, f64)> {
    overlapping_circles(&discs(circles), arena)
        .into_iter()
        .find(|&(i, j, depth)| {
            let (a, b) = (&circles[i], &circles[j]);
            depth > rounding_slack(a.position, a.radius).max(rounding_slack(b.position, b.radius))
        })
}
