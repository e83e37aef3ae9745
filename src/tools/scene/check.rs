//! Checking what an input file says before anything runs: [`Scene::to_config`] turns a parsed
//! scene into a [`CirclesConfig`] through the configuration's own checks
//! ([`CirclesConfig::check`]) plus what only a file has — explicit circles, each inside the
//! arena ([`check_circle`]) and none overlapping another beyond rounding ([`first_overlap`]).
//! Every error names the file and the field.

use std::f64::consts::PI;
use std::ops::ControlFlow;
use std::path::Path;

use bevy::math::DVec2;

use super::schema::Scene;
use crate::base::arena::Arena;
use crate::base::circle::{CircleState, discs};
use crate::base::components::Tint;
use crate::base::config::{CirclesConfig, MIN_RADIUS_FRACTION, SpawnConfig, min_radius};
use crate::base::error::{FieldError, InputError};
use crate::base::range::{MAX_MAGNITUDE, check_magnitude, check_mass, check_vector};
use crate::base::segment::{MAX_SEGMENTS, SegmentCells, Segments, check_end};
use crate::collision::broad_phase::visit_overlapping_pairs;
use crate::solvers::discrete::pass::separate_overlaps;
use crate::tools::io::{MAX_SCENE_BYTES, read_limited};

impl Scene {
    /// Reads and checks a scene file into a configuration.
    pub fn load(path: &Path) -> Result<CirclesConfig, InputError> {
        Self::read(path)?.to_config(&path.display().to_string())
    }

    /// Reads a scene file as it is written, unchecked ([`Scene::to_config`] checks it).
    pub fn read(path: &Path) -> Result<Self, InputError> {
        let origin = path.display().to_string();
        let text = std::fs::File::open(path)
            .map_err(|e| format!("cannot read: {e}"))
            .and_then(|file| read_limited(file, MAX_SCENE_BYTES))
            .map_err(|message| InputError::whole(&origin, message))?;
        Self::parse(&text, &origin)
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
        check_vector("arena.size", size).map_err(field_error)?;
        if !(size.x > 0.0 && size.y > 0.0) {
            return Err(field_error(FieldError::new(
                "arena.size",
                format!("must be two positive numbers, got {size}"),
            )));
        }
        check_vector("arena.center", self.arena.center).map_err(field_error)?;
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
        let segments = check_polylines(&self.segments, &arena).map_err(field_error)?;
        let mut config = CirclesConfig {
            arena,
            spawn,
            solver: self.solver,
            effects: self.effects,
            dt: self.dt,
            circles: Vec::with_capacity(self.circles.len()),
            segments,
            drop: self.drop,
            soft: self.soft,
        };
        config.check().map_err(field_error)?;
        for (i, spec) in self.circles.iter().enumerate() {
            let within = |e: FieldError| field_error(e.within(&format!("circles[{i}]")));
            let mass = match (spec.immovable, spec.mass) {
                (true, None) => f64::INFINITY,
                (true, Some(_)) => {
                    let why = "an immovable circle's mass is infinite; give no `mass`";
                    return Err(within(FieldError::new("mass", why)));
                }
                // check_circle takes an infinite mass as a static circle; a scene says so in
                // words.
                (false, Some(m)) => match check_mass("mass", m) {
                    Err(range) if m.is_infinite() => {
                        let why = format!("{} (a static circle: `immovable: true`)", range.message);
                        return Err(within(FieldError::new("mass", why)));
                    }
                    _ => m,
                },
                (false, None) => self.mass.mass_of(spec.radius),
            };
            let circle = CircleState {
                position: spec.position,
                velocity: spec.velocity,
                radius: spec.radius,
                mass,
                tint: spec.color.unwrap_or(Tint::default().0),
                angular_velocity: spec.angular_velocity,
                rotation: 0.0,
            };
            check_circle(&circle, &arena).map_err(within)?;
            config.circles.push(circle);
        }
        // With its explicit circles in, gravity is checked against them too.
        config.check_gravity_scale().map_err(field_error)?;
        if self.separate_overlaps {
            check_separable(&config.circles, &arena).map_err(field_error)?;
            separate_overlaps(&mut config.circles, &arena);
        }
        let walls = SegmentCells::over_arena(&config.segments.0, &arena);
        for (i, c) in config.circles.iter().enumerate() {
            if let Some(k) = walls.first_touched(&config.segments.0, c.position, c.radius) {
                let (line, n) = polyline_of(&self.segments, k as usize);
                let why = format!("overlaps segments[{line}] (its segment {n}: segment wall {k})");
                return Err(field_error(FieldError::new(format!("circles[{i}]"), why)));
            }
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

/// The segment walls of a scene's polylines, each checked: at least two points, every point
/// inside `arena`, at most [`MAX_SEGMENTS`] in all (counted before any is made).
fn check_polylines(polylines: &[Vec<DVec2>], arena: &Arena) -> Result<Segments, FieldError> {
    let mut count = 0usize;
    for (i, line) in polylines.iter().enumerate() {
        if line.len() < 2 {
            let why = format!("a polyline needs at least two points, got {}", line.len());
            return Err(FieldError::new(format!("segments[{i}]"), why));
        }
        count = count.saturating_add(line.len() - 1);
        for (k, &p) in line.iter().enumerate() {
            check_end(&format!("segments[{i}][{k}]"), p, arena)?;
        }
    }
    if count > MAX_SEGMENTS {
        let why = format!("{count} segments; at most {MAX_SEGMENTS} are supported");
        return Err(FieldError::new("segments", why));
    }
    Ok(Segments::from_polylines(polylines))
}

/// Which polyline segment wall `k` comes from, and its place in it.
fn polyline_of(polylines: &[Vec<DVec2>], mut k: usize) -> (usize, usize) {
    for (i, line) in polylines.iter().enumerate() {
        let n = line.len().saturating_sub(1);
        if k < n {
            return (i, k);
        }
        k -= n;
    }
    (polylines.len(), k)
}

/// Checks what a run changes of a circle against the range every reader holds values to: its
/// position and velocity ([`check_vector`]) and how it turns ([`check_spin`]). A run may leave
/// that range from inputs at its edge (a light circle hit by heavier ones at 10³⁰ m/s goes
/// faster still); what it then writes would be refused on reading, so it writes nothing.
pub fn check_motion(c: &CircleState) -> Result<(), FieldError> {
    check_vector("position", c.position)?;
    check_vector("velocity", c.velocity)?;
    check_spin(c)
}

/// Checks how a circle turns: its rotation in `[-π, π]` (where every solver keeps it) and its
/// surface no faster than any speed an input may give.
pub fn check_spin(c: &CircleState) -> Result<(), FieldError> {
    if !(-PI..=PI).contains(&c.rotation) {
        let why = format!("must be in [-π, π], got {:?}", c.rotation);
        return Err(FieldError::new("rotation", why));
    }
    if check_magnitude("", c.angular_velocity * c.radius).is_err() {
        let why = format!(
            "must be finite, its surface no faster than {MAX_MAGNITUDE:e}, got {:?}",
            c.angular_velocity
        );
        return Err(FieldError::new("angular_velocity", why));
    }
    Ok(())
}

/// Checks one explicit circle: finite, positive radius, a mass in range or infinite (a static
/// circle, which must be at rest), inside the arena (entirely, with walls; its centre, when
/// periodic; anywhere, when open), not larger than it.
pub fn check_circle(c: &CircleState, arena: &Arena) -> Result<(), FieldError> {
    check_vector("position", c.position)?;
    check_vector("velocity", c.velocity)?;
    if c.mass == f64::INFINITY && c.velocity != DVec2::ZERO {
        return Err(FieldError::new(
            "velocity",
            "an immovable (infinite-mass) circle in a file is static: it must be at rest \
             (kinematic circles are steered by code)",
        ));
    }
    if !(c.radius.is_finite() && c.radius > 0.0) {
        return Err(FieldError::new(
            "radius",
            format!("must be positive and finite, got {}", c.radius),
        ));
    }
    if c.mass != f64::INFINITY {
        check_mass("mass", c.mass)?;
    }
    check_spin(c)?;
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
    if arena.is_open() {
        return Ok(()); // no edge to be inside of: anywhere in range
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

/// Most overlapping pairs per circle that `separate_overlaps` takes on: more than a packing
/// can hold, so only circles piled on one another exceed it. Each separation sweep lists the
/// overlapping pairs, so the cap also bounds its memory.
pub const MAX_OVERLAPS_PER_CIRCLE: usize = 16;

/// Refuses circles piled too deep to push apart, counting overlapping pairs only up to the cap.
fn check_separable(circles: &[CircleState], arena: &Arena) -> Result<(), FieldError> {
    let cap = MAX_OVERLAPS_PER_CIRCLE * circles.len();
    let mut pairs = 0;
    let _ = visit_overlapping_pairs(arena, &discs(circles), |_, _| {
        pairs += 1;
        if pairs > cap {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    if pairs > cap {
        return Err(FieldError::new(
            "separate_overlaps",
            format!(
                "the circles overlap in more than {MAX_OVERLAPS_PER_CIRCLE} pairs per circle: \
                 they are piled on one another, not jostled; spread them out"
            ),
        ));
    }
    Ok(())
}

/// A pair of circles that overlaps by more than rounding, `(i, j, depth)` with `i < j`, if
/// there is one. Stops at the first it meets, so an input of N circles at one point costs
/// O(N) memory, not a list of N² pairs.
pub fn first_overlap(circles: &[CircleState], arena: &Arena) -> Option<(usize, usize, f64)> {
    let discs = discs(circles);
    let mut found = None;
    let _ = visit_overlapping_pairs(arena, &discs, |i, j| {
        let (a, b) = (&circles[i], &circles[j]);
        let depth = a.radius + b.radius - arena.offset(a.position, b.position).length();
        if depth > rounding_slack(a.position, a.radius).max(rounding_slack(b.position, b.radius)) {
            found = Some((i, j, depth));
            return ControlFlow::Break(());
        }
        ControlFlow::Continue(())
    });
    found
}
