//! The accuracy study behind `moving_circles accuracy`: the same scenes under every solver and
//! setting, each measured against the `exact` solver (the reference) and timed, to show what
//! accuracy costs.
//!
//! - [`measure`]: one run ([`trace`]) and its comparison with the reference ([`compare`]);
//! - [`report`]: the rows as CSV and as a table;
//! - [`front`]: the error measures the figure shows and the Pareto front of each;
//! - [`plot`]: the figure, as SVG and PNG;
//! - [`piles`]: the pile scenes, measured on their own terms (overlap at rest, energy left,
//!   time to settle, cost) and the cheapest setting per overlap budget;
//! - [`auto`]: `--solver auto`, the cheapest solver within a tolerance on the user's scene.

pub mod auto;
pub mod front;
pub mod measure;
pub mod piles;
#[cfg(feature = "cli")]
pub mod plot;
pub mod report;

use std::path::Path;

pub use measure::{
    Case, HORIZON_SECONDS, REFERENCE_DT, Row, SOLVERS, Trace, compare, passed_through, trace,
};

use crate::base::config::CirclesConfig;
use crate::base::error::InputError;
use crate::tools::scene::Scene;

/// The study's steps: 30, 60 and 120 Hz, or 60 Hz alone when `quick`.
pub fn steps(quick: bool) -> &'static [f64] {
    if quick {
        &[1.0 / 60.0]
    } else {
        &[1.0 / 30.0, 1.0 / 60.0, 1.0 / 120.0]
    }
}

/// The scene `name` of the study from `scenes_dir`, refused if it has no circle to measure
/// (every error of the study would be 0/0).
fn load_case(scenes_dir: &Path, name: &str) -> Result<CirclesConfig, InputError> {
    let path = scenes_dir.join(format!("{name}.ron"));
    let config = Scene::load(&path)?;
    let placed = config.circles.len() + config.spawn.target_count(&config.arena);
    if placed == 0 && config.drop.is_none() {
        return Err(InputError::whole(
            &path.display().to_string(),
            "has no circles for the study to measure",
        ));
    }
    Ok(config)
}

/// The study's cases (gas1k, gas, billiards, fast, and the rough gas, where rotation matters),
/// from the scene files in `scenes_dir`; shorter runs when `quick`.
pub fn default_cases(scenes_dir: &Path, quick: bool) -> Result<Vec<Case>, InputError> {
    // Billiards is compared after the break (the cue ball reaches the rack at about 0.21 s).
    let plan = [
        ("gas1k", 5.0, 1.0, HORIZON_SECONDS),
        ("gas", 2.0, 0.5, HORIZON_SECONDS),
        ("billiards", 2.0, 1.0, 0.3),
        ("fast", 2.0, 0.5, HORIZON_SECONDS),
        ("rough_gas", 5.0, 1.0, HORIZON_SECONDS),
    ];
    plan.into_iter()
        .map(|(name, seconds, quick_seconds, horizon)| {
            Ok(Case {
                name: name.to_owned(),
                config: load_case(scenes_dir, name)?,
                seconds: if quick { quick_seconds } else { seconds },
                horizon,
            })
        })
        .collect()
}

/// The study's pile scenes (the Galton board for 45 s, the 2000-circle pile for 20 s), from the
/// scene files in `scenes_dir`; when `quick`, the pyramid for 2 s.
pub fn pile_cases(scenes_dir: &Path, quick: bool) -> Result<Vec<Case>, InputError> {
    let plan: &[(&str, f64)] = if quick {
        &[("pyramid", 2.0)]
    } else {
        &[("galton", 45.0), ("pile", 20.0)]
    };
    plan.iter()
        .map(|&(name, seconds)| {
            Ok(Case {
                name: name.to_owned(),
                config: load_case(scenes_dir, name)?,
                seconds,
                horizon: seconds,
            })
        })
        .collect()
}
