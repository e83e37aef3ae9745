//! [`Effects`]: which effects a scene calls for and their parameters (restitution, roughness, friction,
//! gravity, drag, collision messages, sleeping), with the one `check` scenes and the command
//! line use; [`Combine`], how two circles' friction meets; and [`SleepConfig`], when circles
//! at rest fall asleep.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::error::FieldError;
use crate::base::range::{MAX_MAGNITUDE, check_vector};

/// The effects a scene calls for. Only these get systems in the schedule: no gravity, no
/// gravity system; no collisions, no broad phase.
///
/// # A circle's own restitution, friction and spin
///
/// `restitution` and `wall_restitution`, `friction` and `wall_friction` are the scene's; a
/// circle's own [`Restitution`](crate::base::components::Restitution) or
/// [`Friction`](crate::base::components::Friction) takes their place for that circle. Two
/// restitutions meet as their minimum (the deader surface decides), against circles and walls
/// alike and under every solver, so the default of 1 never makes a pair bouncier than either
/// side asks; two friction coefficients meet as `friction_combine` says.
///
/// Friction acts under the contact solver `soft`: each contact gets a tangent row (Coulomb: at
/// most μ times its normal push; a ball on a slope rolls without slipping at (2/3) g sin θ when
/// μ ≥ tan θ / 3, and slips otherwise) and a rolling row (a torque of at most
/// `rolling_resistance` times the push times the radius), both warm started and kept in
/// checkpoints. Each circle turns by its
/// [`AngularVelocity`](crate::base::components::AngularVelocity) under every solver, as a
/// uniform disc (m r² / 2) unless it has its own
/// [`Inertia`](crate::base::components::Inertia); a circle without an `AngularVelocity` never
/// turns (friction then only slows its sliding). Under `swept` and `exact` hits can be rough
/// instead (`tangential_restitution`, `wall_tangential_restitution`; the repository's
/// `docs/physics.md` has the rule); `discrete` and `substeps=N` treat circles as smooth and
/// turn each at its own constant rate. The report gives the energy of turning
/// (`rotational_final`, also in `energy_final`) and the angular momentum about the origin. The
/// app draws a darker radius on each disc, turned by its
/// [`Rotation`](crate::base::components::Rotation); a game's own sprite reads `Rotation` the
/// same way (the transform sync leaves a `Transform`'s rotation to the game).
///
/// ```
/// use bevy::math::DVec2;
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// fn spawn_balls(mut commands: Commands) {
///     // A dead ball: it meets everything with a restitution of 0.2 at most.
///     commands.spawn((Radius(0.3), Position(DVec2::new(0.0, 3.0)), Restitution(0.2)));
///     // A ball struck with backspin: under `soft` it skids, then rolls back towards where it
///     // came from.
///     commands.spawn((
///         Radius(0.3),
///         Position(DVec2::new(-2.0, -4.2)),
///         Velocity(DVec2::new(3.0, 0.0)),
///         AngularVelocity(40.0),
///         Friction(0.4),
///     ));
///     // A hollow ring: all its mass at the rim, so it rolls down a slope at half of g sin θ.
///     commands.spawn((Radius(0.5), Position(DVec2::new(2.0, -4.0)), Inertia(0.5 * 0.5)));
/// }
/// # bevy::ecs::system::assert_is_system(spawn_balls);
/// ```
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct Effects {
    /// Circle-circle collisions, under every solver. Off, circles pass through each other: the
    /// time-stepped solvers schedule no broad phase, the event-driven ones predict no pair,
    /// `soft` makes no contact between circles.
    pub collisions: bool,
    /// Constant acceleration, e.g. `(0, -9.81)`; `None` schedules no gravity system.
    pub gravity: Option<DVec2>,
    /// Linear drag rate in 1/s (`v' = -drag · v`); `None` schedules no drag system.
    pub drag: Option<f64>,
    /// Coefficient of restitution between circles: 1 is perfectly elastic.
    pub restitution: f64,
    /// Coefficient of restitution against the walls.
    pub wall_restitution: f64,
    /// Coefficient of friction between circles (Coulomb's μ, 0 or more): a contact's push
    /// along its surface is at most μ times its push along the normal. 0, the default, is
    /// smooth. Friction acts under the contact solver `soft`, which then turns circles
    /// ([`AngularVelocity`](crate::base::components::AngularVelocity)); the other solvers treat
    /// circles as smooth.
    pub friction: f64,
    /// Coefficient of friction against arena walls and segment walls.
    pub wall_friction: f64,
    /// How two friction coefficients meet (a circle's own [`Friction`](crate::base::components::Friction)
    /// and its partner's, or the walls'): their geometric mean by default.
    pub friction_combine: Combine,
    /// Rolling resistance (dimensionless, 0 or more): a rolling circle is slowed by a torque
    /// of this times its contact's push times its radius (the smaller radius of two circles),
    /// so a ball rolling on a floor stops after a while. Under `soft`, with friction.
    pub rolling_resistance: f64,
    /// Tangential restitution β between circles, from −1 to 1: how rough their hits are under
    /// the event solvers `swept` and `exact`. At each hit the slip of the two surfaces at the
    /// contact becomes −β times what it was, trading energy between moving and turning: −1,
    /// the default, is smooth (no spin traded), +1 perfectly rough (no energy lost when the
    /// restitution is 1 too). The contact solver `soft` has friction instead.
    pub tangential_restitution: f64,
    /// Tangential restitution β between a circle and a wall (arena or segment wall).
    pub wall_tangential_restitution: f64,
    /// Write a [`CircleHit`](crate::base::hits::CircleHit) message per circle-circle impulse and a
    /// [`WallHit`](crate::base::hits::WallHit) per wall hit, under every solver. Off (the
    /// default), nothing is recorded and no system is added.
    ///
    /// `swept` and `exact` write each at its exact event time, in time order; `discrete` and
    /// `substeps=N` at the end of the (sub)step that resolved it, for every (sub)step a pair
    /// still overlaps and approaches; `soft` when a contact begins to push (at the step's end,
    /// `time = dt`), not for each step a resting contact goes on pushing. The messages equal
    /// the counters (`tests/suite/hits.rs`, every solver): one `CircleHit` per pair collision,
    /// and the `WallHit`s' `count`s add up to the wall hits (a step that carries a circle across
    /// the arena and back gives one message that counts every hit). A system with a
    /// `MessageReader<CircleHit>` (in `Update`, or in `FixedUpdate` after
    /// [`CircleSystems::Step`](crate::step::schedule::CircleSystems::Step)) sees each hit once;
    /// the [crate's front page](crate) reads them in a headless app.
    pub hit_messages: bool,
    /// When circles at rest fall asleep (only under gravity: without it nothing rests).
    pub sleep: SleepConfig,
}

/// When circles at rest fall asleep. A circle is at rest while it stays within `speed · time`
/// radii of where it last moved, that is, while it moves slower than `speed` on average; a
/// group of touching circles sleeps once every one of them has been at rest for `time` seconds.
/// A sleeping circle costs nothing per step and wakes when hit, when your code writes its
/// `Position` or `Velocity`, or when the effects change. Only scenes with gravity sleep: without
/// it nothing rests.
#[derive(Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SleepConfig {
    /// Whether circles may sleep at all.
    pub enabled: bool,
    /// Mean speed below which a circle counts as at rest, in radii per second. Measured by
    /// displacement rather than velocity, so the resting contacts of the discrete solvers,
    /// whose velocities shake by what gravity gives in a substep, rest too.
    pub speed: f64,
    /// How long a group must stay at rest before it sleeps, in seconds.
    pub time: f64,
}

impl Default for SleepConfig {
    /// Box2D's defaults: 0.05 m/s for a body of radius 0.5 m, for 0.5 s.
    fn default() -> Self {
        Self {
            enabled: true,
            speed: 0.1,
            time: 0.5,
        }
    }
}

/// How two friction coefficients `a` and `b` meet at a contact. Each rule gives `a` when both
/// are `a`, so circles that all take the scene's coefficient meet with exactly it.
#[derive(Reflect, Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Combine {
    /// `√(a·b)` (Box2D's rule): a frictionless side makes the contact frictionless.
    #[default]
    GeometricMean,
    /// `(a + b) / 2` (avian's default).
    Average,
    /// The smaller.
    Min,
    /// The larger.
    Max,
}

impl Combine {
    /// The coefficient of a contact between surfaces of coefficients `a` and `b`.
    ///
    /// ```
    /// use moving_circles::base::config::Combine;
    ///
    /// assert_eq!(Combine::GeometricMean.apply(0.5, 0.5), 0.5);
    /// assert_eq!(Combine::GeometricMean.apply(0.0, 0.9), 0.0);
    /// assert_eq!(Combine::Max.apply(0.2, 0.6), 0.6);
    /// ```
    #[inline]
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Combine::GeometricMean if a == b => a,
            Combine::GeometricMean => (a * b).sqrt(),
            Combine::Average => 0.5 * (a + b),
            Combine::Min => a.min(b),
            Combine::Max => a.max(b),
        }
    }
}

/// The largest friction coefficient or rolling resistance an input may give (μ = 1 already
/// holds a ball on a 45° slope).
pub const MAX_FRICTION: f64 = 100.0;

impl Default for Effects {
    fn default() -> Self {
        Self {
            collisions: true,
            gravity: None,
            drag: None,
            restitution: 1.0,
            wall_restitution: 1.0,
            friction: 0.0,
            wall_friction: 0.0,
            friction_combine: Combine::GeometricMean,
            rolling_resistance: 0.0,
            tangential_restitution: -1.0,
            wall_tangential_restitution: -1.0,
            hit_messages: false,
            sleep: SleepConfig::default(),
        }
    }
}

impl Effects {
    /// Whether any contact has friction or rolling resistance (a circle's own `Friction` aside).
    pub fn has_friction(&self) -> bool {
        self.friction > 0.0 || self.wall_friction > 0.0 || self.rolling_resistance > 0.0
    }

    /// Whether any hit is rough (a tangential restitution above −1).
    pub fn is_rough(&self) -> bool {
        self.tangential_restitution > -1.0 || self.wall_tangential_restitution > -1.0
    }

    /// Whether every parameter is usable: restitutions in `[0, 1]`, tangential restitutions in
    /// `[-1, 1]`, friction coefficients and rolling resistance from 0 to [`MAX_FRICTION`],
    /// finite gravity, a finite non-negative drag rate.
    pub fn check(&self) -> Result<(), FieldError> {
        let unit = |x: f64| x.is_finite() && (0.0..=1.0).contains(&x);
        if !unit(self.restitution) {
            return Err(FieldError::new(
                "effects.restitution",
                format!("must be in [0, 1], got {}", self.restitution),
            ));
        }
        if !unit(self.wall_restitution) {
            return Err(FieldError::new(
                "effects.wall_restitution",
                format!("must be in [0, 1], got {}", self.wall_restitution),
            ));
        }
        let tangential = [
            (
                "effects.tangential_restitution",
                self.tangential_restitution,
            ),
            (
                "effects.wall_tangential_restitution",
                self.wall_tangential_restitution,
            ),
        ];
        for (field, value) in tangential {
            if !(-1.0..=1.0).contains(&value) {
                let why = format!("must be in [-1, 1] (-1 smooth, 1 perfectly rough), got {value}");
                return Err(FieldError::new(field, why));
            }
        }
        let coefficients = [
            ("effects.friction", self.friction),
            ("effects.wall_friction", self.wall_friction),
            ("effects.rolling_resistance", self.rolling_resistance),
        ];
        for (field, value) in coefficients {
            if !(0.0..=MAX_FRICTION).contains(&value) {
                let why = format!("must be from 0 to {MAX_FRICTION}, got {value}");
                return Err(FieldError::new(field, why));
            }
        }
        if let Some(g) = self.gravity {
            check_vector("effects.gravity", g)?;
        }
        if let Some(drag) = self.drag
            && !(0.0..=MAX_MAGNITUDE).contains(&drag)
        {
            return Err(FieldError::new(
                "effects.drag",
                format!("must be a rate from 0 to {MAX_MAGNITUDE:e} (1/s), got {drag}"),
            ));
        }
        let sleep = [
            ("effects.sleep.speed", self.sleep.speed),
            ("effects.sleep.time", self.sleep.time),
        ];
        for (field, value) in sleep {
            if !(0.0..=MAX_MAGNITUDE).contains(&value) {
                let why = format!("must be from 0 to {MAX_MAGNITUDE:e}, got {value}");
                return Err(FieldError::new(field, why));
            }
        }
        Ok(())
    }
}
