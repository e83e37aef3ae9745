//! [`SoftConfig`]: the tuning of the `soft` contact solver (how stiff and how damped a contact
//! is, how fast an overlap is pushed out, below which speed a hit does not bounce), with its
//! `check`.
//!
//! Speeds are given in radii per second (of the pair's smaller circle), so one setting fits a
//! Galton board's 9 cm balls and a pile of 1 m boulders alike: Box2D's defaults, stated in
//! metres for bodies about 1 m across, are these numbers at a radius of 0.5 m.

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::error::FieldError;
use crate::base::range::MAX_MAGNITUDE;

/// How the `soft` solver's contacts behave: soft constraints (a spring of `hertz` with
/// `damping_ratio`, twice as stiff against immovable bodies and walls), overlap pushed out at
/// no more than `push_speed`, and, under gravity, restitution only for hits faster than
/// `restitution_threshold`.
#[derive(Resource, Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
#[serde(default, deny_unknown_fields)]
pub struct SoftConfig {
    /// Stiffness of a contact, as the frequency of the spring it stands for (Hz). Capped at a
    /// quarter of the substep rate, where a stiffer spring would no longer be stable.
    pub hertz: f64,
    /// Damping ratio of that spring: above 1, overdamped (no rebound from the push-out).
    pub damping_ratio: f64,
    /// Fastest speed at which an overlap is pushed out, in radii per second.
    pub push_speed: f64,
    /// Under gravity, hits approaching slower than this (radii per second) do not bounce:
    /// resting contacts then do not jitter. 0 bounces every hit. Without gravity nothing
    /// rests, and every hit bounces whatever this is.
    pub restitution_threshold: f64,
}

impl Default for SoftConfig {
    /// Box2D v3's damping ratio (10), push-out (3 m/s) and restitution threshold (1 m/s) for
    /// bodies of radius 0.5 m, with springs twice as stiff as its 30 Hz: 60 Hz.
    fn default() -> Self {
        Self {
            hertz: 60.0,
            damping_ratio: 10.0,
            push_speed: 6.0,
            restitution_threshold: 2.0,
        }
    }
}

impl SoftConfig {
    /// Whether every value is usable: a positive frequency and push speed, a non-negative
    /// damping ratio and threshold, all finite and within the physical range.
    pub fn check(&self) -> Result<(), FieldError> {
        let positive = [
            ("soft.hertz", self.hertz),
            ("soft.push_speed", self.push_speed),
        ];
        for (field, value) in positive {
            if !(value > 0.0 && value <= MAX_MAGNITUDE) {
                let why = format!("must be positive and at most {MAX_MAGNITUDE:e}, got {value}");
                return Err(FieldError::new(field, why));
            }
        }
        let non_negative = [
            ("soft.damping_ratio", self.damping_ratio),
            ("soft.restitution_threshold", self.restitution_threshold),
        ];
        for (field, value) in non_negative {
            if !(0.0..=MAX_MAGNITUDE).contains(&value) {
                let why = format!("must be from 0 to {MAX_MAGNITUDE:e}, got {value}");
                return Err(FieldError::new(field, why));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_values_name_their_field() {
        let bad = SoftConfig {
            hertz: 0.0,
            ..SoftConfig::default()
        };
        assert_eq!(bad.check().unwrap_err().field, "soft.hertz");
        let bad = SoftConfig {
            restitution_threshold: f64::NAN,
            ..SoftConfig::default()
        };
        assert_eq!(bad.check().unwrap_err().field, "soft.restitution_threshold");
        assert!(SoftConfig::default().check().is_ok());
    }
}
