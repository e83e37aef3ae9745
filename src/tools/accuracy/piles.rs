//! The study's pile scenes: what a game asks of a solver on a heap under gravity, measured on
//! its own terms. A pile has no reference to compare with (which circle ends where is chaos,
//! and `exact` freezes circles where they first rest), so each run is measured absolutely:
//! - `max_penetration`: the deepest overlap after any step (falling impacts included), and
//!   `rest_penetration`: the deepest in the final state, both in smaller radii;
//! - `energy_left`: the kinetic energy at the end over `N·m·g·r` (mean mass and radius of the
//!   movable circles);
//! - `settled_at`: when the kinetic energy last fell below [`SETTLED`] `·N·m·g·r` to stay there
//!   (`None`: it never did);
//! - `asleep`, `escaped`, `budget_exhausted`, and the cost of stepping as in [`Row`](super::Row).
//!
//! [`pile_picks`] reads off, per scene and overlap budget, the cheapest setting that settles
//! within the budget at rest: what the README's "what to pick" is for piles.

use serde::{Deserialize, Serialize};

use super::measure::Case;
use crate::base::config::Solver;
use crate::tools::run::{headless_app, run_steps};

/// Kinetic energy (over `N·m·g·r`) below which a pile counts as settled.
pub const SETTLED: f64 = 1e-4;

/// The solvers the pile study runs ([`Solver::PILE_STUDY`]): the course's, the contact solver
/// at two substep counts and the event-driven ones.
pub const PILE_SOLVERS: [Solver; 7] = Solver::PILE_STUDY;

/// Overlap budgets at rest (smaller radii) the picks are read for: a tenth, Box2D's slop at
/// r = 0.5 (a fiftieth), and rounding.
pub const PILE_BUDGETS: [f64; 3] = [0.1, 0.02, 1e-9];

/// One run of a pile scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PileRow {
    /// Scene name.
    pub scene: String,
    /// Circles at the end.
    pub n: usize,
    /// Solver.
    pub solver: String,
    /// Step in seconds.
    #[serde(deserialize_with = "number_or_nan")]
    pub dt: f64,
    /// Stepping cost per step.
    #[serde(deserialize_with = "number_or_nan")]
    pub ms_per_step: f64,
    /// Stepping cost per simulated second.
    #[serde(deserialize_with = "number_or_nan")]
    pub ms_per_sim_second: f64,
    /// Deepest overlap after any step, in smaller radii.
    #[serde(deserialize_with = "number_or_nan")]
    pub max_penetration: f64,
    /// Deepest overlap in the final state, in smaller radii.
    #[serde(deserialize_with = "number_or_nan")]
    pub rest_penetration: f64,
    /// Kinetic energy at the end over `N·m·g·r`.
    #[serde(deserialize_with = "number_or_nan")]
    pub energy_left: f64,
    /// Simulated seconds after which the kinetic energy stayed below [`SETTLED`] `·N·m·g·r`.
    pub settled_at: Option<f64>,
    /// Circles asleep at the end.
    pub asleep: usize,
    /// Centres outside the arena at the end.
    pub escaped: usize,
    /// Steps whose event budget ran out.
    pub budget_exhausted: u64,
}

/// A number as serde_json wrote it, where one that is not finite became `null`.
fn number_or_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Runs the pile `case` (a scene with gravity) under `solver` at step `dt` and measures it.
/// A `soft` solver keeps the scene's own contact settings.
pub fn measure_pile(case: &Case, solver: Solver, dt: f64) -> PileRow {
    let config = crate::base::config::CirclesConfig {
        solver,
        dt,
        ..case.config.clone()
    };
    let g = config.effects.gravity.map_or(0.0, |g| g.length());
    let mut app = headless_app(config);
    let steps = (case.seconds / dt).round().max(1.0) as u64;
    // The first step of the last stretch below the settled energy, if it lasts to the end.
    let (mut scale, mut below_since) = (0.0, Some(0u64));
    let report = run_steps(&mut app, &case.name, steps, 1, |mut sample| {
        let circles = sample.circles();
        let movable = circles.iter().filter(|c| c.mass.is_finite());
        let (count, mass, radius, kinetic) = movable.fold((0.0, 0.0, 0.0, 0.0), |acc, c| {
            let kinetic = 0.5 * c.mass * c.velocity.length_squared();
            (
                acc.0 + 1.0,
                acc.1 + c.mass,
                acc.2 + c.radius,
                acc.3 + kinetic,
            )
        });
        scale = if count > 0.0 {
            mass * g * radius / count
        } else {
            0.0
        };
        if kinetic > SETTLED * scale {
            below_since = None;
        } else if below_since.is_none() {
            below_since = Some(sample.step);
        }
    });
    let per_second = |ms: f64| ms / dt;
    PileRow {
        scene: case.name.clone(),
        n: report.n,
        solver: solver.to_string(),
        dt,
        ms_per_step: report.ms_per_step,
        ms_per_sim_second: per_second(report.ms_per_step),
        max_penetration: report.max_penetration,
        rest_penetration: report.final_penetration,
        energy_left: if scale > 0.0 {
            report.kinetic_final / scale
        } else {
            0.0
        },
        settled_at: below_since.map(|step| step as f64 * dt),
        asleep: report.sleeping,
        escaped: report.escaped,
        budget_exhausted: report.budget_exhausted,
    }
}

/// Per scene and overlap budget, the cheapest setting (by ms per simulated second) that left
/// no circle out, settled, and rests within the budget; `None` where no setting did.
pub fn pile_picks(rows: &[PileRow]) -> Vec<(String, f64, Option<&PileRow>)> {
    let mut scenes: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
    scenes.dedup();
    let mut picks = Vec::new();
    for scene in scenes {
        for budget in PILE_BUDGETS {
            let best = rows
                .iter()
                .filter(|r| r.scene == scene && r.escaped == 0 && r.settled_at.is_some())
                .filter(|r| r.rest_penetration <= budget)
                .min_by(|a, b| a.ms_per_sim_second.total_cmp(&b.ms_per_sim_second));
            picks.push((scene.to_owned(), budget, best));
        }
    }
    picks
}

/// The pile study as a fixed-width table, then the picks.
pub fn pile_table(rows: &[PileRow]) -> String {
    let mut out = format!(
        "{:<9} {:>5} {:<12} {:>5} {:>9} {:>9} {:>9} {:>9} {:>8} {:>7} {:>6}\n",
        "pile",
        "n",
        "solver",
        "1/dt",
        "ms/sim s",
        "max pen",
        "rest pen",
        "E left",
        "settled",
        "asleep",
        "budget"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<9} {:>5} {:<12} {:>5.0} {:>9.2} {:>9.2e} {:>9.2e} {:>9.1e} {:>8} {:>7} {:>6}\n",
            r.scene,
            r.n,
            r.solver,
            1.0 / r.dt,
            r.ms_per_sim_second,
            r.max_penetration,
            r.rest_penetration,
            r.energy_left,
            r.settled_at
                .map_or_else(|| "never".to_owned(), |t| format!("{t:.1} s")),
            r.asleep,
            r.budget_exhausted,
        ));
    }
    out.push_str("Cheapest setting that settles within an overlap at rest of:\n");
    for (scene, budget, pick) in pile_picks(rows) {
        let what = pick.map_or_else(
            || "none".to_owned(),
            |r| {
                format!(
                    "{} at {:.0} Hz ({:.2} ms per simulated second)",
                    r.solver,
                    1.0 / r.dt,
                    r.ms_per_sim_second
                )
            },
        );
        out.push_str(&format!("{scene:<9} {budget:>7.0e}  {what}\n"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_with_a_number_that_is_not_finite_reads_back_from_json() {
        let row = PileRow {
            scene: "pile".into(),
            n: 3,
            solver: "soft".into(),
            dt: 0.5,
            ms_per_step: 1.0,
            ms_per_sim_second: 2.0,
            max_penetration: f64::NAN,
            rest_penetration: f64::INFINITY,
            energy_left: 0.25,
            settled_at: None,
            asleep: 0,
            escaped: 0,
            budget_exhausted: 0,
        };
        // serde_json writes NaN and infinity as `null`.
        let back: PileRow = serde_json::from_str(&serde_json::to_string(&row).unwrap()).unwrap();
        assert!(back.max_penetration.is_nan() && back.rest_penetration.is_nan());
        assert_eq!(back.energy_left, 0.25);
    }
}
