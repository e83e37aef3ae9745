//! [`Effects`]: which effects a scene calls for and their parameters (restitution, gravity,
//! drag, collision messages), with the one `check` scenes and the command line use.

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
        Ok(())
    }
}
