//! The one physical range every number read from an input must lie in — lengths, coordinates,
//! speeds, masses, densities, accelerations and rates — so that nothing a run computes from
//! them (energies, momenta, the virial, pressure) can overflow. Scene files, particle files,
//! spawn rules, checkpoints and the command line all check through these.

use bevy::math::DVec2;

use crate::base::error::FieldError;

/// Largest magnitude of any length, coordinate, speed, mass, density, acceleration or rate an
/// input may give. One rule for scene files, particle files, spawn rules and the command line:
/// with every value within it, energies, momenta and the virial of a run stay finite
/// (`½·m·v²` summed over the most circles an input may ask for is below 10⁹⁸).
pub const MAX_MAGNITUDE: f64 = 1e30;
/// Smallest mass an input may give (inverse masses stay at most [`MAX_MAGNITUDE`]).
pub const MIN_MASS: f64 = 1e-30;

/// Checks that `value` is finite and at most [`MAX_MAGNITUDE`] in size.
pub fn check_magnitude(field: &str, value: f64) -> Result<(), FieldError> {
    if value.is_finite() && value.abs() <= MAX_MAGNITUDE {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!("must be finite and at most {MAX_MAGNITUDE:e} in size, got {value:?}"),
        ))
    }
}

/// Whether both components of `value` are finite and at most [`MAX_MAGNITUDE`] in size.
pub fn in_range(value: DVec2) -> bool {
    value.is_finite() && value.abs().max_element() <= MAX_MAGNITUDE
}

/// [`check_magnitude`] for both components of a vector.
pub fn check_vector(field: &str, value: DVec2) -> Result<(), FieldError> {
    if in_range(value) {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!(
                "must be finite and at most {MAX_MAGNITUDE:e} in size, got ({:?}, {:?})",
                value.x, value.y
            ),
        ))
    }
}

/// Checks that `mass` is within [`MIN_MASS`, `MAX_MAGNITUDE`].
pub fn check_mass(field: &str, mass: f64) -> Result<(), FieldError> {
    if (MIN_MASS..=MAX_MAGNITUDE).contains(&mass) {
        Ok(())
    } else {
        Err(FieldError::new(
            field,
            format!("must be between {MIN_MASS:e} and {MAX_MAGNITUDE:e}, got {mass:?}"),
        ))
    }
}
