//! The rules that tie a spec's fields together: what its measure and its figure need of its
//! scene, length and axes.

use super::spec::{Axis, Combine, SweepSpec, TaskMeasure};
use crate::base::config::Solver;
use crate::base::error::FieldError;

impl SweepSpec {
    /// The `report` measure runs the scene for the length; the `eos` measure places its own
    /// disks, runs until it has its collisions, and varies only area fraction and seed.
    pub(super) fn check_measure(&self) -> Result<(), FieldError> {
        let TaskMeasure::Eos(eos) = &self.measure else {
            if self.scene.is_none() {
                return Err(FieldError::new("scene", "missing: the scene the tasks run"));
            }
            if self.length.is_none() {
                return Err(FieldError::new(
                    "length",
                    "missing: how long each task runs, `steps(N)` or `seconds(T)`",
                ));
            }
            return Ok(());
        };
        let refuse = |field: &str, why: &str| Err(FieldError::new(field, why));
        if self.scene.is_some() {
            return refuse(
                "scene",
                "the `eos` measure places its own disks: give no scene",
            );
        }
        if self.length.is_some() {
            return refuse(
                "length",
                "the `eos` measure runs until it has its collisions: give no length",
            );
        }
        for (k, axis) in self.axes.iter().enumerate() {
            match axis {
                Axis::AreaFraction(values) => {
                    eos.check(values, &format!("axes[{k}].area_fraction"))?
                }
                Axis::Seed(_) => {}
                other => {
                    return Err(FieldError::new(
                        format!("axes[{k}]"),
                        format!(
                            "the `eos` measure varies `area_fraction` and `seed` alone, not {}",
                            other.sets()
                        ),
                    ));
                }
            }
        }
        if !self.axes.iter().any(|a| matches!(a, Axis::AreaFraction(_))) {
            return refuse("axes", "the `eos` measure needs an `area_fraction` axis");
        }
        Ok(())
    }

    /// The `eos` figure draws z against the area fraction, the mean over seeds with its
    /// standard error (or, with the `eos` measure and one seed, its blocks' error): the spec
    /// varies those two and nothing else.
    pub(super) fn check_eos_figure(&self) -> Result<(), FieldError> {
        let axis = |f: fn(&Axis) -> bool| self.axes.iter().find(|a| f(a)).map_or(0, Axis::len);
        if axis(|a| matches!(a, Axis::AreaFraction(_))) == 0 {
            return Err(FieldError::new(
                "figure",
                "`eos` draws z against area fraction: the spec needs an `area_fraction` axis",
            ));
        }
        // The `eos` measure's tasks have block error bars of their own.
        let seeds_needed = if self.measure == TaskMeasure::Report {
            2
        } else {
            1
        };
        if axis(|a| matches!(a, Axis::Seed(_))).max(1) < seeds_needed
            || self.combine == Combine::Zip
        {
            return Err(FieldError::new(
                "figure",
                "`eos` draws the standard error over seeds: the spec needs a `seed` axis of two \
                 or more, combined by `product`",
            ));
        }
        let other = self
            .axes
            .iter()
            .position(|a| !matches!(a, Axis::AreaFraction(_) | Axis::Seed(_)) && a.len() > 1);
        if let Some(k) = other {
            return Err(FieldError::new(
                "figure",
                format!(
                    "`eos` averages over seeds alone, but axes[{k}] varies {} too: sweep each \
                     of its values in a spec of its own",
                    self.axes[k].sets()
                ),
            ));
        }
        Ok(())
    }

    /// The `accuracy` figure compares each setting with `exact` at 60 Hz: the solvers include
    /// `exact`, and a `dt` axis (else the scene's step) includes 1/60 s.
    pub(super) fn check_accuracy_figure(&self) -> Result<(), FieldError> {
        let exact = Solver::REFERENCE.to_string();
        let has_reference = self.axes.iter().any(|a| match a {
            Axis::Solver(names) => names.iter().any(|n| n.parse() == Ok(Solver::REFERENCE)),
            _ => false,
        });
        if !has_reference || self.combine == Combine::Zip {
            return Err(FieldError::new(
                "figure",
                format!(
                    "`accuracy` compares each setting with `{exact}`: the spec needs a `solver` \
                     axis that includes \"{exact}\", combined by `product`"
                ),
            ));
        }
        let dts = self.axes.iter().find_map(|a| match a {
            Axis::Dt(v) => Some(v),
            _ => None,
        });
        if let Some(dts) = dts
            && !dts.iter().any(|&dt| is_reference_dt(dt))
        {
            return Err(FieldError::new(
                "figure",
                format!(
                    "`accuracy` compares each setting with `{exact}` at 60 Hz: the `dt` axis \
                     needs 0.016666666666666666 (1/60) among its values"
                ),
            ));
        }
        Ok(())
    }
}

/// Whether `dt` is the accuracy study's reference step, 1/60 s (written to any number of
/// digits that read back within a millionth).
pub fn is_reference_dt(dt: f64) -> bool {
    (dt / crate::tools::accuracy::REFERENCE_DT - 1.0).abs() < 1e-6
}
