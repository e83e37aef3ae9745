//! [`CircleState`]: one circle's state as plain data, outside the ECS — what spawning places, what
//! scene and particle files hold, what the kernels and the event engine take in, and what a
//! [`snapshot`] of the world gives back.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::components::{Mass, Position, Radius, Tint, Velocity};

/// The state of one circle.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::circle::CircleState;
///
/// let heavy = CircleState::new(DVec2::ZERO, DVec2::X, 0.5).with_mass(f64::INFINITY);
/// assert_eq!(heavy.inv_mass(), 0.0); // immovable: collision kernels need no special case
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CircleState {
    /// Centre.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// Radius.
    pub radius: f64,
    /// Mass; `f64::INFINITY` is immovable.
    pub mass: f64,
    /// Colour as sRGB bytes.
    pub tint: [u8; 3],
}

impl CircleState {
    /// A circle of unit mass and the default tint.
    pub fn new(position: DVec2, velocity: DVec2, radius: f64) -> Self {
        Self {
            position,
            velocity,
            radius,
            mass: 1.0,
            tint: Tint::default().0,
        }
    }

    /// The same circle with another mass.
    pub fn with_mass(self, mass: f64) -> Self {
        Self { mass, ..self }
    }

    /// `1 / mass`, zero for an infinite mass (see [`Mass::inverse`]).
    #[inline]
    pub fn inv_mass(&self) -> f64 {
        Mass(self.mass).inverse()
    }

    /// The components of this circle, ready to spawn.
    pub fn bundle(&self) -> (Radius, Position, Velocity, Mass, Tint) {
        (
            Radius(self.radius),
            Position(self.position),
            Velocity(self.velocity),
            Mass(self.mass),
            Tint(self.tint),
        )
    }
}

/// Every circle in the world, in query order (the order they were spawned in).
pub fn snapshot(world: &mut World) -> Vec<CircleState> {
    world
        .query::<(&Position, &Velocity, &Radius, &Mass, &Tint)>()
        .iter(world)
        .map(|(p, v, r, m, t)| from_components(p, v, r, m, t))
        .collect()
}

/// [`snapshot`] with each circle's entity.
pub fn snapshot_with_entities(world: &mut World) -> Vec<(Entity, CircleState)> {
    world
        .query::<(Entity, &Position, &Velocity, &Radius, &Mass, &Tint)>()
        .iter(world)
        .map(|(e, p, v, r, m, t)| (e, from_components(p, v, r, m, t)))
        .collect()
}

fn from_components(p: &Position, v: &Velocity, r: &Radius, m: &Mass, t: &Tint) -> CircleState {
    CircleState {
        position: p.0,
        velocity: v.0,
        radius: r.0,
        mass: m.0,
        tint: t.0,
    }
}

/// Centres and radii of `circles`: what the broad phase and the overlap queries read.
pub fn discs(circles: &[CircleState]) -> Vec<(DVec2, f64)> {
    circles.iter().map(|c| (c.position, c.radius)).collect()
}
