//! Measuring one run of the study and comparing it with the reference: [`trace`] steps a case
//! with one solver and step through the shared [`run_steps`] loop, watching for pairs that
//! [`passed_through`] each other; [`compare`] turns a trace and the `exact` reference's into a
//! [`Row`].
//!
//! What a row holds (all dimensionless unless said):
//! - `position_error`: RMS distance from the reference's circles after a short horizon
//!   ([`HORIZON_SECONDS`]), in mean radii (chaos makes longer horizons meaningless);
//! - `energy_drift`, `momentum_drift` (periodic scenes; relative to `Σ m|v|`);
//! - `max_penetration`, `mean_penetration`: overlaps after each step, in smaller radii;
//! - `tunnelled`: pairs of circles that flew straight through a step (velocities unchanged),
//!   whose straight paths went through overlap, and that ended apart on the far side (a lower
//!   bound: a pair that also hit something else in the same step is not counted); `escaped`:
//!   centres outside;
//! - `collision_error`: (pair collisions − reference's) / reference's;
//! - `z` and `z_error` (pressure from the virial, relative to the reference), `speed_ks`
//!   (Kolmogorov–Smirnov distance of the final speed distribution from the reference's);
//! - `turning_error`: (energy of turning at the end − the reference's) / the reference's, where
//!   the reference turns circles (rough hits): −1 for a solver that treats circles as smooth;
//! - cost: `ms_per_step` and `ms_per_sim_second` of stepping alone.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::circle::{CircleState, snapshot};
use crate::base::config::{CirclesConfig, Solver};
use crate::collision::broad_phase::{CellList, overlapping_pairs};
use crate::game::diagnostics::relative_change;
use crate::tools::run::{Report, headless_app, run_steps};

/// Default simulated time after which positions are compared with the reference: a few
/// collisions per circle in the study's gases, before chaos makes every comparison meaningless.
pub const HORIZON_SECONDS: f64 = 0.1;

/// The reference's step: every run of a case is compared with `exact` at 60 Hz.
pub const REFERENCE_DT: f64 = 1.0 / 60.0;

/// The solvers the study compares ([`Solver::STUDY`]), cheapest first by design (the
/// measurement decides); the last, `exact`, is the reference.
pub const SOLVERS: [Solver; 9] = Solver::STUDY;

/// One scene of the study.
#[derive(Clone, Debug)]
pub struct Case {
    /// Name in the table.
    pub name: String,
    /// What to simulate.
    pub config: CirclesConfig,
    /// How long to run each setting.
    pub seconds: f64,
    /// When positions are compared with the reference.
    pub horizon: f64,
}

/// What one run did, before it is compared with the reference.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Trace {
    /// Solver used.
    pub solver: Solver,
    /// Step used.
    pub dt: f64,
    /// The run's report: cost, energy, momentum, overlaps, collisions, pressure.
    pub report: Report,
    /// State at the horizon.
    pub at_horizon: Vec<CircleState>,
    /// State at the end.
    pub at_end: Vec<CircleState>,
    /// Pairs that passed through each other.
    pub tunnelled: u64,
    /// Mean radius (for the position error's unit).
    pub mean_radius: f64,
}

/// Runs `case` with one solver and step, measuring after every step (outside the timed
/// stepping).
pub fn trace(case: &Case, solver: Solver, dt: f64) -> Trace {
    let config = CirclesConfig {
        solver,
        dt,
        ..case.config.clone()
    };
    let arena = config.arena;
    let mut app = headless_app(config);
    let steps = (case.seconds / dt).round().max(1.0) as u64;
    let horizon_step = ((case.horizon / dt).round().max(1.0) as u64).min(steps);
    let mut before = snapshot(app.world_mut());
    let mean_radius = before.iter().map(|c| c.radius).sum::<f64>() / before.len().max(1) as f64;
    let (mut tunnelled, mut at_horizon) = (0, Vec::new());
    let report = run_steps(&mut app, &case.name, steps, 1, |mut sample| {
        let now = sample.circles();
        tunnelled += passed_through(&before, &now, &arena);
        if sample.step == horizon_step {
            at_horizon = now.clone();
        }
        before = now;
    });
    Trace {
        solver,
        dt,
        report,
        at_horizon,
        at_end: before,
        tunnelled,
        mean_radius,
    }
}

/// Pairs that passed through each other during one step, from the states before and after it:
/// both kept their velocities (nothing hit them), their straight relative path went through
/// overlap, and they end apart on opposite sides. Circles must be in the same order.
pub fn passed_through(before: &[CircleState], after: &[CircleState], arena: &Arena) -> u64 {
    let moves = |i: usize| arena.offset(before[i].position, after[i].position);
    let free: Vec<bool> = (0..before.len())
        .map(|i| before[i].velocity == after[i].velocity)
        .collect();
    // Any such pair overlaps when each radius is grown by the circle's displacement.
    let reach: Vec<(DVec2, f64)> = (0..before.len())
        .map(|i| (before[i].position, before[i].radius + moves(i).length()))
        .collect();
    let mut candidates = Vec::new();
    overlapping_pairs(&mut CellList::default(), arena, &reach, &mut candidates);
    candidates
        .into_iter()
        .filter(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            if !(free[i] && free[j]) {
                return false;
            }
            let sigma = before[i].radius + before[j].radius;
            let a = arena.offset(before[i].position, before[j].position);
            let b = a + moves(j) - moves(i);
            if a.length() < sigma || b.length() < sigma || a.dot(b) >= 0.0 {
                return false;
            }
            let m = b - a;
            let s = (-a.dot(m) / m.length_squared()).clamp(0.0, 1.0);
            (a + m * s).length() < sigma
        })
        .count() as u64
}

/// One row of the study: a run compared with its case's reference.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// Case name.
    pub scene: String,
    /// Circles.
    pub n: usize,
    /// Solver name.
    pub solver: String,
    /// Step in seconds.
    pub dt: f64,
    /// Steps run.
    pub steps: u64,
    /// Stepping cost per step.
    pub ms_per_step: f64,
    /// Stepping cost per simulated second.
    pub ms_per_sim_second: f64,
    /// When positions were compared (simulated seconds).
    pub horizon: f64,
    /// RMS distance from the reference at the horizon, in mean radii.
    pub position_error: f64,
    /// Relative change of mechanical energy.
    pub energy_drift: f64,
    /// Change of total momentum relative to `Σ m|v|` (meaningful in periodic scenes).
    pub momentum_drift: f64,
    /// Deepest overlap after any step, in smaller radii.
    pub max_penetration: f64,
    /// Mean overlap of overlapping pairs after steps, in smaller radii.
    pub mean_penetration: f64,
    /// Pairs that passed through each other.
    pub tunnelled: u64,
    /// Centres outside the arena at the end.
    pub escaped: usize,
    /// Pair collisions.
    pub pair_collisions: u64,
    /// (collisions − reference's) / reference's.
    pub collision_error: f64,
    /// Compressibility factor from the virial.
    pub z: Option<f64>,
    /// Relative difference of `z` from the reference's.
    pub z_error: Option<f64>,
    /// KS distance of the final speed distribution from the reference's.
    pub speed_ks: f64,
    /// Relative difference of the final energy of turning from the reference's, where the
    /// reference has any.
    pub turning_error: Option<f64>,
}

/// Compares `run` with `reference` (both of `case`).
pub fn compare(case: &Case, run: &Trace, reference: &Trace) -> Row {
    let arena = case.config.arena;
    let rms = |a: &[CircleState], b: &[CircleState]| {
        let sum: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| arena.offset(x.position, y.position).length_squared())
            .sum();
        (sum / a.len().max(1) as f64).sqrt()
    };
    let r = &run.report;
    let scale: f64 = run
        .at_end
        .iter()
        .map(|c| c.mass * c.velocity.length())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    let momentum_change =
        DVec2::from_array(r.momentum_final) - DVec2::from_array(r.momentum_initial);
    let ms = r.wall_seconds * 1e3;
    Row {
        scene: case.name.clone(),
        n: r.n,
        solver: run.solver.to_string(),
        dt: run.dt,
        steps: r.steps,
        ms_per_step: ms / r.steps as f64,
        ms_per_sim_second: ms / (r.steps as f64 * run.dt),
        horizon: case.horizon,
        position_error: rms(&run.at_horizon, &reference.at_horizon) / run.mean_radius,
        energy_drift: r.energy_drift,
        momentum_drift: momentum_change.length() / scale,
        max_penetration: r.max_penetration,
        mean_penetration: r.mean_penetration,
        tunnelled: run.tunnelled,
        escaped: r.escaped,
        pair_collisions: r.pair_collisions,
        collision_error: relative_change(
            reference.report.pair_collisions as f64,
            r.pair_collisions as f64,
        ),
        z: r.z,
        z_error: r.z.zip(reference.report.z).map(|(z, zr)| (z - zr) / zr),
        speed_ks: ks_distance(&run.at_end, &reference.at_end),
        turning_error: (reference.report.rotational_final > 0.0)
            .then(|| relative_change(reference.report.rotational_final, r.rotational_final)),
    }
}

fn ks_distance(a: &[CircleState], b: &[CircleState]) -> f64 {
    let sorted = |s: &[CircleState]| {
        let mut v: Vec<f64> = s.iter().map(|c| c.velocity.length()).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    let (a, b) = (sorted(a), sorted(b));
    let (mut i, mut j, mut d) = (0, 0, 0.0f64);
    while i < a.len() && j < b.len() {
        if a[i] <= b[j] {
            i += 1;
        } else {
            j += 1;
        }
        d = d.max((i as f64 / a.len() as f64 - j as f64 / b.len() as f64).abs());
    }
    d
}
