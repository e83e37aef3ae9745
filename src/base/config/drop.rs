//! [`DropConfig`]: circles dropped into the arena one at a time while it runs (a Galton board's
//! balls, an hourglass's sand), with the one `check` scenes and code use.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::error::FieldError;
use crate::base::range::{check_magnitude, check_mass, check_vector};

use super::spawn::{MIN_RADIUS_FRACTION, min_radius};
use super::{MAX_CIRCLES, MassModel};

/// Drops `count` circles of `radius`, one every `every` simulated seconds, at `position` moved
/// sideways by up to `spread` (seeded), with `velocity`. A drop waits while the spot is taken.
/// In a scene: `drop: (count: 200, every: 0.1, position: (0.0, 7.4), spread: 0.3, radius: 0.09)`
/// (the Galton board's, `assets/scenes/galton.ron`).
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct DropConfig {
    /// How many circles to drop in all.
    pub count: usize,
    /// Simulated seconds between two drops.
    pub every: f64,
    /// Where each circle appears (before the sideways spread).
    pub position: DVec2,
    /// Largest sideways offset; offsets are uniform in `[-spread, spread]`.
    pub spread: f64,
    /// Radius of every dropped circle.
    pub radius: f64,
    /// Velocity each circle starts with.
    pub velocity: DVec2,
    /// Seed of the sideways offsets and colours.
    pub seed: u64,
}

impl Default for DropConfig {
    fn default() -> Self {
        Self {
            count: 100,
            every: 0.25,
            position: DVec2::ZERO,
            spread: 0.0,
            radius: 0.1,
            velocity: DVec2::ZERO,
            seed: 1,
        }
    }
}

impl DropConfig {
    /// Whether the drops fit `arena`: a positive interval, a radius that fits (and is not below
    /// the least radius a circle there may have), a mass from `mass` (the spawn rules' model)
    /// within range, every drop point inside with walls to spare, at most [`MAX_CIRCLES`]. Fields are named relative to
    /// the drop rules (`every`, `radius`, …).
    pub fn check(&self, arena: &Arena, mass: MassModel) -> Result<(), FieldError> {
        if self.count > MAX_CIRCLES {
            let why = format!(
                "asks for {} circles; at most {MAX_CIRCLES} are supported",
                self.count
            );
            return Err(FieldError::new("count", why));
        }
        if !(self.every.is_finite() && self.every > 0.0) {
            let why = format!("must be a positive number of seconds, got {}", self.every);
            return Err(FieldError::new("every", why));
        }
        check_magnitude("radius", self.radius)?;
        if !(self.radius > 0.0 && 2.0 * self.radius <= arena.size().min_element()) {
            let why = format!("must be positive and fit the arena, got {}", self.radius);
            return Err(FieldError::new("radius", why));
        }
        if self.radius < min_radius(arena) {
            let why = format!(
                "must be at least {MIN_RADIUS_FRACTION:?} of the arena's smaller side ({:?}), \
                 got {:?}",
                min_radius(arena),
                self.radius
            );
            return Err(FieldError::new("radius", why));
        }
        check_mass("mass", mass.mass_of(self.radius)).map_err(|e| {
            let why = format!(
                "the spawn rules' mass model gives a drop a mass that {}",
                e.message
            );
            FieldError::new("radius", why)
        })?;
        check_vector("position", self.position)?;
        check_vector("velocity", self.velocity)?;
        if !(self.spread.is_finite() && self.spread >= 0.0) {
            let why = format!("must be a distance of 0 or more, got {}", self.spread);
            return Err(FieldError::new("spread", why));
        }
        let reach = DVec2::new(self.spread + self.radius, self.radius);
        let (lo, hi) = (self.position - reach, self.position + reach);
        if !(lo.cmpge(arena.min).all() && hi.cmple(arena.max).all()) {
            let why = format!(
                "{} ± {} with radius {} must lie inside the arena, which spans {} to {}",
                self.position, self.spread, self.radius, arena.min, arena.max
            );
            return Err(FieldError::new("position", why));
        }
        Ok(())
    }
}
