//! [`Effects`]: which effects a scene calls for and their parameters (restitution, gravity,
//! drag, collision messages, sleeping), with the one `check` scenes and the command line use;
//! and [`SleepConfig`], when circles at rest fall asleep.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::FieldError;
use crate::range::{MAX_MAGNITUDE, check_vector};

/// The effects a scene calls for. Only these get systems in the schedule: no gravity, no
/// gravity system; no collisions, no broad phase.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct Effects {
    /// Circle-circle collisions (broad phase, separation and impulse).
    pub collisions: bool,
    /// Constant acceleration, e.g. `(0, -9.81)`; `None` schedules no gravity system.
    pub gravity: Option<DVec2>,
    /// Linear drag rate in 1/s (`v' = -drag · v`); `None` schedules no drag system.
    pub drag: Option<f64>,
    /// Coefficient of restitution between circles: 1 is perfectly elastic.
    pub restitution: f64,
    /// Coefficient of restitution against the walls.
    pub wall_restitution: f64,
    /// Write a [`CircleHit`](crate::hits::CircleHit) message per circle-circle impulse and a
    /// [`WallHit`](crate::hits::WallHit) per wall hit, under every solver. Off, nothing is
    /// recorded.
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

impl Default for Effects {
    fn default() -> Self {
        Self {
            collisions: true,
            gravity: None,
            drag: None,
            restitution: 1.0,
            wall_restitution: 1.0,
            hit_messages: false,
            sleep: SleepConfig::default(),
        }
    }
}

impl Effects {
    /// Whether every parameter is usable: restitutions in `[0, 1]`, finite gravity, a finite
    /// non-negative drag rate.
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
