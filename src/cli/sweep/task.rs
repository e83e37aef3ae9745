//! One task of a sweep, as `tasks.jsonl` lists it: the settings its axes give it.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// How long a task runs.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpecLength {
    /// Fixed steps.
    Steps(u64),
    /// Simulated seconds.
    Seconds(f64),
}

/// One task of a sweep: the scene's settings with what the axes set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Task {
    /// Its index in the sweep (Slurm's array index).
    pub index: usize,
    /// The solver, if an axis sets it (else the scene's).
    pub solver: Option<String>,
    /// The fixed step, if an axis sets it.
    pub dt: Option<f64>,
    /// The placement seed, if an axis sets it.
    pub seed: Option<u64>,
    /// The area fraction, if an axis sets it.
    pub area_fraction: Option<f64>,
    /// How long it runs (with the `report` measure).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<SpecLength>,
    /// The scene fields its `field` axes set, by path.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fields: BTreeMap<String, serde_json::Value>,
    /// Its own scene file in the sweep's folder (`scenes/K.ron`), when it sets fields.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scene: Option<String>,
}
