//! What each task of a sweep measures: the report of a `run` of the scene (the default), a
//! point of the hard-disk equation of state (as `moving_circles eos` measures one), or a run
//! of the accuracy study (as `moving_circles accuracy` measures one, gas or pile).

use serde::{Deserialize, Serialize};

use crate::base::error::FieldError;
use crate::tools::eos::EosOptions;

/// What a task measures and keeps as its result.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TaskMeasure {
    /// A `run` of the scene with the task's settings for the spec's `length`; its report is
    /// the result, and a task stopped by a signal goes on from its checkpoint.
    #[default]
    Report,
    /// The equation of state at the task's `area_fraction` (and `seed`): `n` equal disks in a
    /// periodic box sized to that fraction, run under `exact`, the first collisions discarded,
    /// then `Z` measured in blocks (`crate::tools::eos::measure`). The spec names no scene and
    /// no length; the result is an `eos.csv` row. A task stopped before it ends starts again.
    Eos(EosMeasure),
    /// A run of the accuracy study under the task's solver and step: its report, and beside it
    /// (`results/I.trace`) its circles at `horizon` seconds and at the end and how many pairs
    /// passed through each other, which `merge` compares with the `exact` task at 60 Hz
    /// (`accuracy.csv`, and the study's five measures in the `accuracy` figure). The spec
    /// varies `solver` and `dt` alone and runs for `seconds(T)`.
    Trace {
        /// When positions are compared, in simulated seconds (the study's 0.1; 0.3 for the
        /// billiards break).
        horizon: f64,
    },
    /// A pile run of the accuracy study under the task's solver and step: overlap at rest,
    /// energy left, time to settle, cost (a `piles.csv` row). The spec varies `solver` and
    /// `dt` alone and runs for `seconds(T)`.
    Pile,
}

/// How an `eos` task measures: the `eos` command's options but the area fractions and seed,
/// which the axes give.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EosMeasure {
    /// Disks in the box.
    pub n: usize,
    /// Collisions per disk run first and discarded.
    pub equilibrate: f64,
    /// Blocks measured after that.
    pub blocks: usize,
    /// Collisions per disk in each block.
    pub block: f64,
}

impl Default for EosMeasure {
    fn default() -> Self {
        let o = EosOptions::default();
        Self {
            n: o.n,
            equilibrate: o.equilibrate,
            blocks: o.blocks,
            block: o.block,
        }
    }
}

impl EosMeasure {
    /// The `eos` command's options for one area fraction and seed.
    pub fn options(&self, area_fraction: f64, seed: u64) -> EosOptions {
        EosOptions {
            n: self.n,
            area_fractions: vec![area_fraction],
            equilibrate: self.equilibrate,
            blocks: self.blocks,
            block: self.block,
            seed,
        }
    }

    /// The measure's own `eos` options from the command's: its area fractions and seed are
    /// the axes'.
    pub fn of_options(options: &EosOptions) -> Self {
        Self {
            n: options.n,
            equilibrate: options.equilibrate,
            blocks: options.blocks,
            block: options.block,
        }
    }

    /// Checks the measure at each of `area_fractions` (the axis at `axis_field`), as the
    /// `eos` command checks its options, each error naming the spec's field.
    pub fn check(&self, area_fractions: &[f64], axis_field: &str) -> Result<(), FieldError> {
        for (k, &phi) in area_fractions.iter().enumerate() {
            self.options(phi, 1).check().map_err(|e| {
                let field = match e.field.as_str() {
                    "--area-fractions" => format!("{axis_field}[{k}]"),
                    flag => format!("measure.eos.{}", flag.trim_start_matches("--")),
                };
                FieldError::new(field, e.message)
            })?;
        }
        Ok(())
    }
}
