//! The rules that tie a spec's fields together: what its measure and its figure need of its
//! scene, length and axes.

use super::spec::{Axis, Combine, SpecLength, SweepFigure, SweepSpec, TaskMeasure};
use crate::base::config::Solver;
use crate::base::error::FieldError;

impl SweepSpec {
    /// The `report` measure runs the scene for the length; the `eos` measure places its own
    /// disks, runs until it has its collisions, and varies only area fraction and seed.
    pub(super) fn check_measure(&self) -> Result<(), FieldError> {
        let figure_fits = matches!(
            (self.figure, &self.measure),
            (None, _)
                | (
                    Some(SweepFigure::Eos),
                    TaskMeasure::Report | TaskMeasure::Eos(_)
                )
                | (
                    Some(SweepFigure::Accuracy),
                    TaskMeasure::Report | TaskMeasure::Trace { .. }
                )
        );
        if !figure_fits {
            return Err(FieldError::new(
                "figure",
                "draws what this measure does not measure: `eos` needs the `report` or `eos` \
                 measure, `accuracy` the `report` or `trace` measure",
            ));
        }
        if self.dump && self.measure != TaskMeasure::Report {
            return Err(FieldError::new(
                "dump",
                "only the `report` measure's tasks are runs that end in a state to keep",
            ));
        }
        if self.boundary.is_some() && self.particles.is_none() {
            return Err(FieldError::new(
                "boundary",
                "goes with a particle file (`particles`); a scene sets its own arena",
            ));
        }
        if self.particles.is_some() && self.measure != TaskMeasure::Report {
            return Err(FieldError::new(
                "particles",
                "only the `report` measure runs a particle file; the others need a scene",
            ));
        }
        if matches!(self.measure, TaskMeasure::Trace { .. } | TaskMeasure::Pile) {
            return self.check_study_measure();
        }
        let TaskMeasure::Eos(eos) = &self.measure else {
            match (&self.scene, &self.particles) {
                (None, None) => {
                    return Err(FieldError::new(
                        "scene",
                        "missing: the scene (or `particles`, a particle file) the tasks run",
                    ));
                }
                (Some(_), Some(_)) => {
                    return Err(FieldError::new(
                        "particles",
                        "give a scene or a particle file, not both",
                    ));
                }
                _ => {}
            }
            if self.particles.is_some()
                && let Some(k) = self.axes.iter().position(|a| {
                    matches!(a, Axis::Seed(_) | Axis::AreaFraction(_) | Axis::Field(..))
                })
            {
                return Err(FieldError::new(
                    format!("axes[{k}]"),
                    format!(
                        "a particle file places every circle itself: it has no {} to vary",
                        self.axes[k].sets()
                    ),
                ));
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

    /// The `trace` and `pile` measures run the scene under each solver and step for a time.
    fn check_study_measure(&self) -> Result<(), FieldError> {
        let name = match self.measure {
            TaskMeasure::Trace { .. } => "trace",
            _ => "pile",
        };
        if self.scene.is_none() {
            return Err(FieldError::new("scene", "missing: the scene the tasks run"));
        }
        let Some(SpecLength::Seconds(seconds)) = self.length else {
            return Err(FieldError::new(
                "length",
                format!("the `{name}` measure runs for a time: give `seconds(T)`"),
            ));
        };
        if let TaskMeasure::Trace { horizon } = self.measure
            && !(horizon > 0.0 && horizon <= seconds)
        {
            return Err(FieldError::new(
                "measure.trace.horizon",
                format!("must be above 0 and at most the length, {seconds} s; got {horizon}"),
            ));
        }
        if let Some(k) = self
            .axes
            .iter()
            .position(|a| !matches!(a, Axis::Solver(_) | Axis::Dt(_)))
        {
            return Err(FieldError::new(
                format!("axes[{k}]"),
                format!(
                    "the `{name}` measure varies `solver` and `dt` alone, not {}",
                    self.axes[k].sets()
                ),
            ));
        }
        // Each trace is compared with `exact` at 60 Hz: the spec must run it.
        if name == "trace" {
            self.check_reference("axes", "the `trace` measure")?;
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
        if self.combine == Combine::Zip {
            return Err(FieldError::new(
                "figure",
                "`eos` groups the tasks by area fraction: combine the axes by `product`",
            ));
        }
        if axis(|a| matches!(a, Axis::Seed(_))).max(1) < seeds_needed {
            return Err(FieldError::new(
                "figure",
                "`eos` draws the standard error over seeds: the spec needs a `seed` axis of two \
                 or more",
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

    /// Without a `dt` axis the tasks run at the scene's step, `dt`: the `accuracy` figure
    /// needs it to be 1/60 s.
    pub(super) fn check_scene_step(&self, dt: f64) -> Result<(), FieldError> {
        let dt_axis = self.axes.iter().any(|a| matches!(a, Axis::Dt(_)));
        let compares = self.figure == Some(SweepFigure::Accuracy)
            || matches!(self.measure, TaskMeasure::Trace { .. });
        if compares && !dt_axis && !is_reference_dt(dt) {
            return Err(FieldError::new(
                "dt",
                format!(
                    "each setting is compared with `exact` at 60 Hz, and the scene's step is \
                     {dt} s: add a `dt` axis with 0.016666666666666666 (1/60)"
                ),
            ));
        }
        Ok(())
    }

    /// The `accuracy` figure compares each setting with `exact` at 60 Hz: the solvers include
    /// `exact`, and a `dt` axis (else the scene's step) includes 1/60 s.
    pub(super) fn check_accuracy_figure(&self) -> Result<(), FieldError> {
        self.check_reference("figure", "`accuracy`")?;
        let steps_axis = self.axes.iter().any(|a| matches!(a, Axis::Steps(_)));
        if steps_axis || matches!(self.length, Some(SpecLength::Steps(_))) {
            return Err(FieldError::new(
                "figure",
                "`accuracy` compares runs over the same simulated time: give `length: \
                 seconds(T)` and no `steps` axis (steps of different sizes cover different times)",
            ));
        }
        Ok(())
    }

    /// What compares each setting with `exact` at 60 Hz (`what`, set by `field`) needs that
    /// task: a `solver` axis with `exact`, combined by `product`, and a `dt` axis, if any, with
    /// 1/60 (else the scene's step: [`SweepSpec::check_scene_step`]).
    fn check_reference(&self, field: &str, what: &str) -> Result<(), FieldError> {
        let exact = Solver::REFERENCE.to_string();
        let has_reference = self.axes.iter().any(|a| match a {
            Axis::Solver(names) => names.iter().any(|n| n.parse() == Ok(Solver::REFERENCE)),
            _ => false,
        });
        if !has_reference || self.combine == Combine::Zip {
            return Err(FieldError::new(
                field,
                format!(
                    "{what} compares each setting with `{exact}`: the spec needs a `solver` \
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
                field,
                format!(
                    "{what} compares each setting with `{exact}` at 60 Hz: the `dt` axis \
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
