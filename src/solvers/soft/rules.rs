//! What every contact of a `soft` step shares ([`ContactRules`]), and the speed a contact
//! bounces from (`impact`).

use bevy::math::DVec2;

use super::bodies::Softness;
use crate::base::config::Combine;

/// The tuning every contact of a step shares.
#[derive(Clone, Copy, Debug)]
pub struct ContactRules {
    /// The fixed step.
    pub dt: f64,
    /// One substep of it.
    pub substep: f64,
    /// Constant acceleration, or zero.
    pub gravity: DVec2,
    /// Restitution between circles and against walls, for circles without their own.
    pub restitution: (f64, f64),
    /// Softness against movable circles, and against immovable ones and walls.
    pub soft: (Softness, Softness),
    /// Push-out speed and restitution threshold, in radii per second.
    pub push_speed: f64,
    /// See [`ContactRules::push_speed`]; 0 without gravity, where nothing rests and every
    /// approach bounces.
    pub threshold: f64,
    /// Whether circles collide with each other at all.
    pub collisions: bool,
    /// Friction between circles and against walls, for circles without their own.
    pub friction: (f64, f64),
    /// How two friction coefficients meet.
    pub combine: Combine,
    /// Rolling resistance (dimensionless).
    pub rolling_resistance: f64,
}

/// The normal velocity a contact bounces from, for two sides whose normal velocity is `now`
/// (negative: approaching), whose relative acceleration along the normal is `accel`
/// (negative: closing) and whose gap is `gap`.
///
/// Under an acceleration that closes the gap (gravity towards a wall or a peg), the speed at
/// impact is what the fall over the gap adds, taken so that the energy the substeps keep
/// (`v²/2 + a·y − a·h·v/2` for symplectic Euler with substep `h`, which moves a circle with
/// its velocity after gravity's kick) is the same after the bounce as before the step: a
/// bounce that reversed the plain impact speed would lose `a·h` of speed at every hit.
pub(super) fn impact(rules: &ContactRules, now: f64, accel: f64, gap: f64) -> f64 {
    if accel >= 0.0 {
        return now;
    }
    let (a, h) = (-accel, rules.substep);
    let fall = if gap > 0.0 { 2.0 * a * gap } else { 0.0 };
    let kick = 0.5 * a * h;
    -(kick
        + (kick * kick + now * now + fall - a * h * now)
            .max(0.0)
            .sqrt())
}
