//! A sweep spec (RON): the scene every task starts from, the axes its tasks vary (solver,
//! step, seed, area fraction, length, any scene field), how they combine, the figure of the
//! merged results, and how the Slurm array runs them; checked like a scene, each error naming
//! its field, and expanded into [`Task`]s.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use super::measure::{EosMeasure, TaskMeasure};
pub use super::slurm::SlurmSettings;
pub use super::task::{SpecLength, Task};
use crate::base::arena::Boundary;
use crate::base::config::{DT_RANGE, Solver};
use crate::base::error::FieldError;

/// Most tasks one sweep may have: a grid that large is a typo (an axis listed twice), and its
/// task list alone would be gigabytes.
pub const MAX_TASKS: usize = 100_000;

/// The longest a spec file may be.
pub const MAX_SPEC_BYTES: u64 = 1 << 20;

/// What a sweep runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// The scene every task starts from, relative to the spec's folder (none with the `eos`
    /// measure, which places its own disks).
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// Instead of a scene, a particle file every task starts from (lines `x y vx vy r [m]`,
    /// as `run --particles` reads them), relative to the spec's folder.
    #[serde(default)]
    pub particles: Option<PathBuf>,
    /// A particle file's edges: `walls` (the default), `periodic` or `open`.
    #[serde(default)]
    pub boundary: Option<Boundary>,
    /// How long each task runs (an axis `steps` overrides it; none with the `eos` measure,
    /// which runs until it has counted its collisions).
    #[serde(default)]
    pub length: Option<SpecLength>,
    /// What each task measures: a `run`'s report (the default), or a point of the equation
    /// of state.
    #[serde(default)]
    pub measure: TaskMeasure,
    /// What the tasks vary.
    #[serde(default)]
    pub axes: Vec<Axis>,
    /// How the axes combine.
    #[serde(default)]
    pub combine: Combine,
    /// How Slurm runs the array.
    #[serde(default)]
    pub slurm: SlurmSettings,
    /// The figure `merge` draws, if any.
    #[serde(default)]
    pub figure: Option<SweepFigure>,
    /// Whether each task also keeps its final state (`results/I.dump.txt`, as `run --dump`
    /// writes it); every task keeps its report.
    #[serde(default)]
    pub dump: bool,
}

/// A figure of the merged results.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SweepFigure {
    /// The equation of state: the report's `z` against the `area_fraction` axis, the mean over
    /// the tasks of each area fraction (the seeds) with its standard error, over Henderson's
    /// and Liu's curves (`eos.svg`, `eos.png`).
    Eos,
    /// What accuracy costs: for each setting of solver and step, cost (ms of stepping per
    /// simulated second) against the errors a report carries (pair collisions and `z`
    /// against the `exact` task at 60 Hz with the same seed and other settings, deepest
    /// overlap), each the mean over the seeds, one row of panels for each setting of the other
    /// axes; the Pareto fronts printed (`accuracy.svg`, `accuracy.png`).
    Accuracy,
}

/// One thing the tasks vary, with its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Axis {
    /// Solvers by name (`exact`, `substeps=4`, `soft=8`, ...).
    Solver(Vec<String>),
    /// Fixed steps in seconds.
    Dt(Vec<f64>),
    /// Placement seeds.
    Seed(Vec<u64>),
    /// The area fraction the scene's random circles fill.
    AreaFraction(Vec<f64>),
    /// Run lengths in steps.
    Steps(Vec<u64>),
    /// Any field of the scene by its path (`effects.restitution`, `arena.size`,
    /// `soft.hertz`, `spawn.radius`), with values as the scene file would give them, an
    /// enum's variant as a string (`"lattice"`). Each task gets a scene file of its own.
    Field(String, Vec<ron::Value>),
}

impl Axis {
    /// Its name in a spec.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Solver(_) => "solver",
            Self::Dt(_) => "dt",
            Self::Seed(_) => "seed",
            Self::AreaFraction(_) => "area_fraction",
            Self::Steps(_) => "steps",
            Self::Field(..) => "field",
        }
    }

    /// What it sets: its name, or a field's path.
    pub(super) fn sets(&self) -> String {
        match self {
            Self::Field(path, _) => format!("field {path:?}"),
            other => format!("`{}`", other.name()),
        }
    }

    /// Its number of values.
    pub fn len(&self) -> usize {
        match self {
            Self::Solver(v) => v.len(),
            Self::Dt(v) | Self::AreaFraction(v) => v.len(),
            Self::Seed(v) | Self::Steps(v) => v.len(),
            Self::Field(_, v) => v.len(),
        }
    }

    /// Whether it has no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sets its `k`-th value on `task`.
    fn set(&self, k: usize, task: &mut Task) {
        match self {
            Self::Solver(v) => task.solver = Some(v[k].clone()),
            Self::Dt(v) => task.dt = Some(v[k]),
            Self::Seed(v) => task.seed = Some(v[k]),
            Self::AreaFraction(v) => task.area_fraction = Some(v[k]),
            Self::Steps(v) => task.length = Some(SpecLength::Steps(v[k])),
            Self::Field(path, v) => {
                task.fields
                    .insert(path.clone(), super::field_axis::json_of(&v[k]));
            }
        }
    }

    /// Checks each value, naming `field` (e.g. `axes[1]`) in an error.
    fn check(&self, field: &str) -> Result<(), FieldError> {
        let field = format!("{field}.{}", self.name());
        if self.is_empty() {
            return Err(FieldError::new(field, "has no values: give at least one"));
        }
        let bad =
            |k: usize, message: String| Err(FieldError::new(format!("{field}[{k}]"), message));
        match self {
            Self::Solver(v) => {
                for (k, name) in v.iter().enumerate() {
                    if let Err(e) = name.parse::<Solver>() {
                        return bad(k, e.to_string());
                    }
                }
            }
            Self::Dt(v) => {
                let (lo, hi) = DT_RANGE;
                for (k, &dt) in v.iter().enumerate() {
                    if !(dt.is_finite() && (lo..=hi).contains(&dt)) {
                        return bad(
                            k,
                            format!("must be between {lo} and {hi} seconds, got {dt}"),
                        );
                    }
                }
            }
            Self::AreaFraction(v) => {
                for (k, &phi) in v.iter().enumerate() {
                    if !(phi.is_finite() && phi > 0.0 && phi < 1.0) {
                        return bad(k, format!("must be between 0 and 1, got {phi}"));
                    }
                }
            }
            Self::Steps(v) => check_steps(v, &field)?,
            Self::Field(path, values) => super::field_axis::check_axis(path, values, &field)?,
            Self::Seed(_) => {}
        }
        // A value given twice is a typo, and would weigh twice in a mean over the axis.
        let repeat = match self {
            // `soft` and `soft=4` are one solver.
            Self::Solver(v) => first_repeat(
                v.iter()
                    .map(|n| n.parse::<Solver>().map_or(n.clone(), |s| s.to_string())),
            ),
            Self::Dt(v) | Self::AreaFraction(v) => first_repeat(v.iter().map(|x| x.to_bits())),
            Self::Seed(v) | Self::Steps(v) => first_repeat(v.iter()),
            Self::Field(_, v) => first_repeat(v.iter()),
        };
        match repeat {
            Some((j, k)) => bad(k, format!("repeats {field}[{j}]")),
            None => Ok(()),
        }
    }
}

/// The first value equal to an earlier one: `(earlier, later)` positions.
fn first_repeat<T: std::hash::Hash + Eq>(items: impl Iterator<Item = T>) -> Option<(usize, usize)> {
    let mut seen = std::collections::HashMap::new();
    items
        .enumerate()
        .find_map(|(k, item)| seen.insert(item, k).map(|j| (j, k)))
}

/// Checks run lengths in steps.
fn check_steps(steps: &[u64], field: &str) -> Result<(), FieldError> {
    let max = crate::cli::run::MAX_STEPS;
    match steps.iter().position(|&s| !(1..=max).contains(&s)) {
        Some(k) => Err(FieldError::new(
            format!("{field}[{k}]"),
            format!("must be from 1 to {max} steps, got {}", steps[k]),
        )),
        None => Ok(()),
    }
}

/// How the axes make tasks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Combine {
    /// Every combination of one value of each axis (the first axis varies slowest).
    #[default]
    Product,
    /// The `k`-th value of every axis together: the axes have the same number of values.
    Zip,
}

impl SweepSpec {
    /// Parses and checks a spec's text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, String> {
        // `scene: "..."` for an optional field, and `eos(n: 4096)` for a variant holding a
        // struct.
        let spec: Self = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .with_default_extension(ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES)
            .from_str(text)
            .map_err(|e| format!("{origin}: {e}"))?;
        spec.check().map_err(|e| format!("{origin}: {e}"))?;
        Ok(spec)
    }

    /// Reads and checks the spec at `path`.
    pub fn read(path: &Path) -> Result<Self, String> {
        let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let text = crate::tools::io::read_limited(file, MAX_SPEC_BYTES)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Checks every field.
    pub fn check(&self) -> Result<(), FieldError> {
        match self.length {
            Some(SpecLength::Steps(steps)) => check_steps(&[steps], "length.steps")?,
            Some(SpecLength::Seconds(s)) if !(s.is_finite() && s > 0.0 && s <= 1e9) => {
                return Err(FieldError::new(
                    "length.seconds",
                    format!("must be above 0 and at most 1e9, got {s}"),
                ));
            }
            Some(SpecLength::Seconds(_)) => {}
            None => {}
        }
        for (k, axis) in self.axes.iter().enumerate() {
            axis.check(&format!("axes[{k}]"))?;
            if let Some(j) = self.axes[..k].iter().position(|a| a.sets() == axis.sets()) {
                return Err(FieldError::new(
                    format!("axes[{k}]"),
                    format!("{} is already axes[{j}]", axis.sets()),
                ));
            }
        }
        if self.combine == Combine::Zip
            && let Some(first) = self.axes.first()
            && let Some(k) = self.axes.iter().position(|a| a.len() != first.len())
        {
            return Err(FieldError::new(
                "combine",
                format!(
                    "`zip` pairs the axes' values one for one, but axes[0] has {} and axes[{k}] {}",
                    first.len(),
                    self.axes[k].len()
                ),
            ));
        }
        self.check_measure()?;
        let tasks = self.task_count();
        if tasks.is_none_or(|n| n > MAX_TASKS) {
            let count = tasks.map_or("more than 2^64".into(), |n| n.to_string());
            return Err(FieldError::new(
                "axes",
                format!("make {count} tasks, more than the {MAX_TASKS} a sweep may have"),
            ));
        }
        match self.figure {
            Some(SweepFigure::Eos) => self.check_eos_figure()?,
            Some(SweepFigure::Accuracy) => self.check_accuracy_figure()?,
            None => {}
        }
        let slurm = &self.slurm;
        if slurm.concurrency == 0 {
            return Err(FieldError::new("slurm.concurrency", "must be at least 1"));
        }
        if !super::slurm::is_slurm_time(&slurm.time_limit) {
            return Err(FieldError::new(
                "slurm.time_limit",
                format!(
                    "{:?} is not a Slurm time such as \"30:00\", \"01:00:00\" or \"2-00:00:00\"",
                    slurm.time_limit
                ),
            ));
        }
        Ok(())
    }

    /// The number of tasks, `None` past `usize`.
    pub fn task_count(&self) -> Option<usize> {
        match self.combine {
            Combine::Product => self
                .axes
                .iter()
                .try_fold(1usize, |n, a| n.checked_mul(a.len())),
            Combine::Zip => Some(self.axes.first().map_or(1, Axis::len)),
        }
    }

    /// Every task, in index order.
    pub fn tasks(&self) -> Vec<Task> {
        let count = self.task_count().expect("a checked spec");
        (0..count)
            .map(|index| {
                let mut task = Task {
                    index,
                    solver: None,
                    dt: None,
                    seed: None,
                    area_fraction: None,
                    length: self.length,
                    fields: BTreeMap::new(),
                    scene: None,
                };
                let mut rest = index;
                // The last axis varies fastest.
                for axis in self.axes.iter().rev() {
                    let k = match self.combine {
                        Combine::Product => {
                            let k = rest % axis.len();
                            rest /= axis.len();
                            k
                        }
                        Combine::Zip => index,
                    };
                    axis.set(k, &mut task);
                }
                task
            })
            .collect()
    }
}
