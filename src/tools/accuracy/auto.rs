//! `--solver auto`: a short calibration run of the user's scene under each candidate solver,
//! measured against `exact`, and the cheapest candidate within the tolerance.

use super::measure::{Case, HORIZON_SECONDS, SOLVERS, compare, trace};
use crate::base::config::{CirclesConfig, Solver};

/// One candidate of `--solver auto`: its error (the larger of position error and max
/// penetration, both in radii) and cost after the calibration run.
#[derive(Clone, Debug, PartialEq)]
pub struct Calibration {
    /// The candidate.
    pub solver: Solver,
    /// `max(position_error, max_penetration)` against `exact`.
    pub error: f64,
    /// Stepping cost.
    pub ms_per_step: f64,
}

/// Picks the cheapest solver whose error stays within `tolerance` on a short calibration run
/// of `config` (about [`HORIZON_SECONDS`], at most 60 steps), measured against `exact`, among
/// the study's [`SOLVERS`]; falls back to `exact`, which meets any tolerance. Returns the
/// choice and every measurement, `exact` last.
pub fn choose_solver(config: &CirclesConfig, tolerance: f64) -> (Solver, Vec<Calibration>) {
    let seconds = HORIZON_SECONDS.min(60.0 * config.dt);
    let case = Case {
        name: "calibration".into(),
        config: config.clone(),
        seconds,
        horizon: seconds,
    };
    let reference = trace(&case, Solver::REFERENCE, config.dt);
    let mut measured: Vec<Calibration> = SOLVERS
        .iter()
        .filter(|&&solver| solver != Solver::REFERENCE)
        .map(|&solver| {
            let row = compare(&case, &trace(&case, solver, config.dt), &reference);
            Calibration {
                solver,
                error: row.position_error.max(row.max_penetration),
                ms_per_step: row.ms_per_step,
            }
        })
        .collect();
    measured.push(Calibration {
        solver: Solver::REFERENCE,
        error: 0.0,
        ms_per_step: reference.report.ms_per_step,
    });
    let choice = measured
        .iter()
        .filter(|c| c.error <= tolerance)
        .min_by(|a, b| a.ms_per_step.total_cmp(&b.ms_per_step))
        .map_or(Solver::REFERENCE, |c| c.solver);
    (choice, measured)
}
