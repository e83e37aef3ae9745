//! [`CircleState`]: one circle's state as plain data, outside the ECS — what spawning places, what
//! scene and particle files hold, what the kernels and the event engine take in, and what a
//! [`snapshot`] of the world gives back.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::components::{
    AngularVelocity, CircleSerial, Mass, Position, Radius, Rotation, Tint, Velocity,
};

/// The moment of inertia of a uniform disc of `mass` and `radius` about its centre: `m r² / 2`,
/// what every circle turns with.
#[inline]
pub fn disc_inertia(mass: f64, radius: f64) -> f64 {
    0.5 * mass * radius * radius
}

/// [`disc_inertia`]'s inverse from the inverse mass: `2 w / r²`; 0 for a circle that cannot
/// turn: immovable (`w = 0`), or so small that `r²` underflows (rather than infinitely easy to
/// turn).
#[inline]
pub fn disc_inverse_inertia(inv_mass: f64, radius: f64) -> f64 {
    let inverse = 2.0 * inv_mass / (radius * radius);
    if inverse.is_finite() { inverse } else { 0.0 }
}

/// The moment of inertia a circle turns with: its `own`
/// ([`Inertia`](crate::base::components::Inertia)) or a uniform disc's.
#[inline]
pub fn inertia(own: Option<f64>, mass: f64, radius: f64) -> f64 {
    own.unwrap_or_else(|| disc_inertia(mass, radius))
}

/// [`inertia`]'s inverse from the inverse mass: 0 for a circle that does not turn from a
/// push: immovable (`w = 0`), or of an own inertia that is infinite or not above 0. An own
/// inertia so small that its inverse passes the range of values (below about 5.6e-309) turns as
/// the smallest whose inverse is finite: an infinite inverse would make every hit's turning
/// `0 × ∞`, not a number.
#[inline]
pub fn inverse_inertia(own: Option<f64>, inv_mass: f64, radius: f64) -> f64 {
    match own {
        _ if inv_mass == 0.0 => 0.0,
        Some(i) if i > 0.0 => (1.0 / i).min(f64::MAX),
        Some(_) => 0.0,
        None => disc_inverse_inertia(inv_mass, radius),
    }
}

/// The state of one circle.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::circle::CircleState;
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
    /// Angular velocity (radians per second, counter-clockwise).
    pub angular_velocity: f64,
    /// How far it has turned (radians, in `[-π, π]`).
    pub rotation: f64,
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
            angular_velocity: 0.0,
            rotation: 0.0,
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
    pub fn bundle(
        &self,
    ) -> (
        Radius,
        Position,
        Velocity,
        Mass,
        Tint,
        AngularVelocity,
        Rotation,
    ) {
        (
            Radius(self.radius),
            Position(self.position),
            Velocity(self.velocity),
            Mass(self.mass),
            Tint(self.tint),
            AngularVelocity(self.angular_velocity),
            Rotation(self.rotation),
        )
    }
}

/// What a circle is made of, as [`snapshot`] reads it (a circle without spin components
/// does not turn).
pub(crate) type Parts = (
    &'static Position,
    &'static Velocity,
    &'static Radius,
    &'static Mass,
    &'static Tint,
    Option<&'static AngularVelocity>,
    Option<&'static Rotation>,
);

/// Every circle in the world, in serial order (the order they were spawned in, which is the
/// order the solvers visit them in: [`CircleSerial`]).
pub fn snapshot(world: &mut World) -> Vec<CircleState> {
    snapshot_with_entities(world)
        .into_iter()
        .map(|(_, c)| c)
        .collect()
}

/// [`snapshot`] with each circle's entity.
pub fn snapshot_with_entities(world: &mut World) -> Vec<(Entity, CircleState)> {
    let mut circles: Vec<(CircleSerial, Entity, CircleState)> = world
        .query::<(Entity, &CircleSerial, Parts)>()
        .iter(world)
        .map(|(e, &serial, parts)| (serial, e, from_components(parts)))
        .collect();
    if !circles.is_sorted_by_key(|c| c.0) {
        circles.sort_unstable_by_key(|c| c.0);
    }
    circles.into_iter().map(|(_, e, c)| (e, c)).collect()
}

pub(crate) fn from_components(
    (p, v, r, m, t, w, a): bevy::ecs::query::QueryItem<'_, '_, Parts>,
) -> CircleState {
    CircleState {
        position: p.0,
        velocity: v.0,
        radius: r.0,
        mass: m.0,
        tint: t.0,
        angular_velocity: w.map_or(0.0, |w| w.0),
        rotation: a.map_or(0.0, |a| a.0),
    }
}

/// Centres and radii of `circles`: what the broad phase and the overlap queries read.
pub fn discs(circles: &[CircleState]) -> Vec<(DVec2, f64)> {
    circles.iter().map(|c| (c.position, c.radius)).collect()
}
