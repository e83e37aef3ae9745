//! The accuracy study behind `moving_circles accuracy`: the same scenes under every solver and
//! setting, each measured against the `exact` solver (the reference) and timed, to show what
//! accuracy costs. Writes a table, a CSV and a log-log plot of error against cost.
//!
//! What is measured, per run (all dimensionless unless said):
//! - `position_error`: RMS distance from the reference's circles after a short horizon
//!   ([`HORIZON_SECONDS`]), in mean radii (chaos makes longer horizons meaningless);
//! - `energy_drift`, `momentum_drift` (periodic scenes; relative to `Σ m|v|`);
//! - `max_penetration`, `mean_penetration`: overlaps after each step, in smaller radii;
//! - `tunnelled`: pairs of circles that flew straight through a step (velocities unchanged),
//!   whose straight paths went through overlap, and that ended apart on the far side: they
//!   passed through each other (a lower bound: a pair that also hit something else in the
//!   same step is not counted); `escaped`: centres outside;
//! - `collision_error`: (pair collisions − reference's) / reference's;
//! - `z` and `z_error` (pressure from the virial, relative to the reference), `speed_ks`
//!   (Kolmogorov–Smirnov distance of the final speed distribution from the reference's);
//! - cost: `ms_per_step` and `ms_per_sim_second` of stepping alone.

use std::path::Path;
use std::time::{Duration, Instant};

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::Serialize;

use crate::collide::broad_phase::{CellList, Space, overlapping_pairs};
use crate::collide::collision_space;
use crate::config::{Boundary, CirclesConfig, Solver};
use crate::diagnostics::{CollisionCounters, Overlaps, Pressure, Totals, relative_change};
use crate::run::{headless_app, snapshot};
use crate::spawn::CircleInit;

/// Default simulated time after which positions are compared with the reference: a few
/// collisions per circle in the study's gases, before chaos makes every comparison meaningless.
pub const HORIZON_SECONDS: f64 = 0.1;

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

/// The solvers and steps every case is run with.
pub fn settings(quick: bool) -> Vec<(Solver, f64)> {
    let solvers = [
        Solver::Discrete,
        Solver::Substeps(2),
        Solver::Substeps(4),
        Solver::Substeps(8),
        Solver::Substeps(16),
        Solver::Swept,
        Solver::Exact,
    ];
    let dts: &[f64] = if quick {
        &[1.0 / 60.0]
    } else {
        &[1.0 / 30.0, 1.0 / 60.0, 1.0 / 120.0]
    };
    dts.iter()
        .flat_map(|&dt| solvers.iter().map(move |&s| (s, dt)))
        .collect()
}

/// What one run did, before it is compared with the reference.
#[derive(Clone, Debug)]
pub struct Trace {
    /// Solver used.
    pub solver: Solver,
    /// Step used.
    pub dt: f64,
    /// Steps run.
    pub steps: u64,
    /// Wall-clock time of stepping alone.
    pub stepping: Duration,
    /// State at the horizon.
    pub at_horizon: Vec<CircleInit>,
    /// State at the end.
    pub at_end: Vec<CircleInit>,
    /// Totals at start and end.
    pub totals: (Totals, Totals),
    /// Counters at the end.
    pub counters: CollisionCounters,
    /// Pressure over the run.
    pub pressure: Pressure,
    /// Deepest overlap after any step, and the mean over overlapping pairs seen.
    pub penetration: (f64, f64),
    /// Pairs that passed through each other.
    pub tunnelled: u64,
    /// Mean radius (for the position error's unit).
    pub mean_radius: f64,
}

/// Runs `case` with one solver and step, measuring as it goes (outside the timed stepping).
pub fn trace(case: &Case, solver: Solver, dt: f64) -> Trace {
    let config = CirclesConfig {
        solver,
        dt,
        ..case.config.clone()
    };
    let space = collision_space(&config.arena, config.effects.boundary);
    let arena = config.arena;
    let gravity = config.effects.gravity;
    let mut app = headless_app(config);
    let steps = (case.seconds / dt).round().max(1.0) as u64;
    let horizon_step = ((case.horizon / dt).round().max(1.0) as u64).min(steps);
    let start_state = snapshot(app.world_mut());
    let totals_of = |s: &[CircleInit]| {
        Totals::measure(
            s.iter().map(|c| (c.position, c.velocity, c.mass)),
            &arena,
            gravity,
        )
    };
    let start_totals = totals_of(&start_state);
    let mean_radius =
        start_state.iter().map(|c| c.radius).sum::<f64>() / start_state.len().max(1) as f64;
    let mut before = start_state.clone();
    let (mut stepping, mut tunnelled) = (Duration::ZERO, 0);
    let (mut max_pen, mut pen_sum, mut pen_pairs) = (0.0f64, 0.0, 0usize);
    let mut at_horizon = Vec::new();
    for step in 1..=steps {
        let t = Instant::now();
        app.update();
        stepping += t.elapsed();
        let now = snapshot(app.world_mut());
        tunnelled += passed_through(&before, &now, space);
        let o = Overlaps::measure(&now, space);
        max_pen = max_pen.max(o.max);
        pen_sum += o.sum;
        pen_pairs += o.pairs;
        if step == horizon_step {
            at_horizon = now.clone();
        }
        before = now;
    }
    let at_end = snapshot(app.world_mut());
    let end_totals = totals_of(&at_end);
    let counters = *app.world().resource::<CollisionCounters>();
    let pressure = Pressure::measure(
        &counters,
        end_totals.count,
        end_totals.kinetic_energy,
        &arena,
        case.config.effects.boundary == Boundary::Walls,
    );
    Trace {
        solver,
        dt,
        steps,
        stepping,
        at_horizon,
        at_end,
        totals: (start_totals, end_totals),
        counters,
        pressure,
        penetration: (
            max_pen,
            if pen_pairs == 0 {
                0.0
            } else {
                pen_sum / pen_pairs as f64
            },
        ),
        tunnelled,
        mean_radius,
    }
}

/// Pairs that passed through each other during one step, from the states before and after it:
/// both kept their velocities (nothing hit them), their straight relative path went through
/// overlap, and they end apart on opposite sides. Circles must be in the same order.
pub fn passed_through(before: &[CircleInit], after: &[CircleInit], space: Space) -> u64 {
    let moves = |i: usize| space.offset(before[i].position, after[i].position);
    let free: Vec<bool> = (0..before.len())
        .map(|i| before[i].velocity == after[i].velocity)
        .collect();
    // Any such pair overlaps when each radius is grown by the circle's displacement.
    let positions: Vec<DVec2> = before.iter().map(|c| c.position).collect();
    let reach: Vec<f64> = (0..before.len())
        .map(|i| before[i].radius + moves(i).length())
        .collect();
    let mut candidates = Vec::new();
    overlapping_pairs(
        &mut CellList::default(),
        space,
        &positions,
        &reach,
        &mut candidates,
    );
    candidates
        .into_iter()
        .filter(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            if !(free[i] && free[j]) {
                return false;
            }
            let sigma = before[i].radius + before[j].radius;
            let a = space.offset(before[i].position, before[j].position);
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
}

/// Compares `run` with `reference` (both of `case`).
pub fn compare(case: &Case, run: &Trace, reference: &Trace) -> Row {
    let rms = |a: &[CircleInit], b: &[CircleInit]| {
        let space = collision_space(&case.config.arena, case.config.effects.boundary);
        let sum: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| space.offset(x.position, y.position).length_squared())
            .sum();
        (sum / a.len().max(1) as f64).sqrt()
    };
    let (t0, t1) = run.totals;
    let scale: f64 = run
        .at_end
        .iter()
        .map(|c| c.mass * c.velocity.length())
        .sum::<f64>()
        .max(f64::MIN_POSITIVE);
    let sim_seconds = run.steps as f64 * run.dt;
    let ms = run.stepping.as_secs_f64() * 1e3;
    Row {
        scene: case.name.clone(),
        n: t1.count,
        solver: run.solver.to_string(),
        dt: run.dt,
        steps: run.steps,
        ms_per_step: ms / run.steps as f64,
        ms_per_sim_second: ms / sim_seconds,
        horizon: case.horizon,
        position_error: rms(&run.at_horizon, &reference.at_horizon) / run.mean_radius,
        energy_drift: relative_change(t0.energy(), t1.energy()),
        momentum_drift: (t1.momentum - t0.momentum).length() / scale,
        max_penetration: run.penetration.0,
        mean_penetration: run.penetration.1,
        tunnelled: run.tunnelled,
        escaped: t1.escaped,
        pair_collisions: run.counters.pair_collisions,
        collision_error: relative_change(
            reference.counters.pair_collisions as f64,
            run.counters.pair_collisions as f64,
        ),
        z: run.pressure.z_virial,
        z_error: run
            .pressure
            .z_virial
            .zip(reference.pressure.z_virial)
            .map(|(z, r)| (z - r) / r),
        speed_ks: ks_distance(&run.at_end, &reference.at_end),
    }
}

fn ks_distance(a: &[CircleInit], b: &[CircleInit]) -> f64 {
    let sorted = |s: &[CircleInit]| {
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

/// The column names of [`Row`] in CSV order.
pub const CSV_HEADER: &str = "scene,n,solver,dt,steps,ms_per_step,ms_per_sim_second,horizon,position_error,energy_drift,momentum_drift,max_penetration,mean_penetration,tunnelled,escaped,pair_collisions,collision_error,z,z_error,speed_ks";

/// The study as CSV text.
pub fn to_csv(rows: &[Row]) -> String {
    let opt = |x: Option<f64>| x.map(|v| format!("{v:e}")).unwrap_or_default();
    let mut out = format!("{CSV_HEADER}\n");
    for r in rows {
        out.push_str(&format!(
            "{},{},{},{:.6},{},{:.6},{:.4},{},{:e},{:e},{:e},{:e},{:e},{},{},{},{:e},{},{},{:.4}\n",
            r.scene,
            r.n,
            r.solver,
            r.dt,
            r.steps,
            r.ms_per_step,
            r.ms_per_sim_second,
            r.horizon,
            r.position_error,
            r.energy_drift,
            r.momentum_drift,
            r.max_penetration,
            r.mean_penetration,
            r.tunnelled,
            r.escaped,
            r.pair_collisions,
            r.collision_error,
            opt(r.z),
            opt(r.z_error),
            r.speed_ks
        ));
    }
    out
}

/// The study as a fixed-width table.
pub fn to_table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:<9} {:>6} {:<12} {:>6} {:>9} {:>9} {:>10} {:>9} {:>9} {:>6} {:>9} {:>8}\n",
        "scene",
        "n",
        "solver",
        "1/dt",
        "ms/step",
        "pos err",
        "E drift",
        "max pen",
        "mean pen",
        "tunnel",
        "coll err",
        "z err"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<9} {:>6} {:<12} {:>6.0} {:>9.3} {:>9.2e} {:>10.1e} {:>9.2e} {:>9.2e} {:>6} {:>+9.3} {:>8}\n",
            r.scene,
            r.n,
            r.solver,
            1.0 / r.dt,
            r.ms_per_step,
            r.position_error,
            r.energy_drift,
            r.max_penetration,
            r.mean_penetration,
            r.tunnelled,
            r.collision_error,
            r.z_error.map(|z| format!("{z:+.3}")).unwrap_or_else(|| "-".into()),
        ));
    }
    out
}

/// Smallest error the plot shows: `exact` against itself is 0, and a log axis needs a floor.
pub const PLOT_FLOOR: f64 = 1e-12;

/// A log-log SVG plot per scene of position error against cost per step.
pub fn plot(rows: &[Row], path: &Path) -> Result<(), String> {
    use plotters::prelude::*;
    let scenes: Vec<&str> = rows.iter().fold(Vec::new(), |mut v, r| {
        if !v.contains(&r.scene.as_str()) {
            v.push(&r.scene);
        }
        v
    });
    let cols = 2usize;
    let rows_of_panels = scenes.len().div_ceil(cols).max(1);
    let root = SVGBackend::new(path, (1200, 460 * rows_of_panels as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let panels = root.split_evenly((rows_of_panels, cols));
    for (scene, panel) in scenes.iter().zip(panels.iter()) {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.scene == *scene).collect();
        let x_range = log_range(mine.iter().map(|r| r.ms_per_step));
        let y_range = log_range(mine.iter().map(|r| r.position_error.max(PLOT_FLOOR)));
        let n = mine.first().map_or(0, |r| r.n);
        let horizon = mine.first().map_or(0.0, |r| r.horizon);
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("{scene} (n = {n}), position error at t = {horizon} s"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .light_line_style(WHITE)
            .x_label_formatter(&|v| format!("{v:.2}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .x_desc("ms per step")
            .y_desc("position error vs exact (mean radii)")
            .draw()
            .map_err(|e| e.to_string())?;
        for (family, colour) in FAMILIES {
            let points: Vec<(f64, f64, String)> = mine
                .iter()
                .filter(|r| r.solver == family)
                .map(|r| {
                    (
                        r.ms_per_step,
                        r.position_error.max(PLOT_FLOOR),
                        format!("{:.0}Hz", 1.0 / r.dt),
                    )
                })
                .collect();
            if points.is_empty() {
                continue;
            }
            let colour = colour.to_rgba();
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|(x, y, _)| Circle::new((*x, *y), 5, colour.filled())),
                )
                .map_err(|e| e.to_string())?
                .label(family)
                .legend(move |(x, y)| Circle::new((x, y), 5, colour.filled()));
            chart
                .draw_series(points.iter().map(|(x, y, label)| {
                    Text::new(
                        label.clone(),
                        (*x, *y),
                        ("sans-serif", 11).into_font().color(&BLACK),
                    )
                }))
                .map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::MiddleRight)
            .draw()
            .map_err(|e| e.to_string())?;
    }
    root.present().map_err(|e| e.to_string())
}

const FAMILIES: [(&str, plotters::style::RGBColor); 7] = [
    ("discrete", plotters::style::RGBColor(220, 50, 47)),
    ("substeps=2", plotters::style::RGBColor(203, 75, 22)),
    ("substeps=4", plotters::style::RGBColor(181, 137, 0)),
    ("substeps=8", plotters::style::RGBColor(133, 153, 0)),
    ("substeps=16", plotters::style::RGBColor(42, 161, 152)),
    ("swept", plotters::style::RGBColor(38, 139, 210)),
    ("exact", plotters::style::RGBColor(108, 113, 196)),
];

fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return 1e-3..1.0;
    }
    (lo / 2.0)..(hi * 2.0)
}

/// The accuracy study's default cases, from the scene files in `scenes_dir`.
pub fn default_cases(
    scenes_dir: &Path,
    quick: bool,
) -> Result<Vec<Case>, crate::scene::InputError> {
    let mut cases = Vec::new();
    // Billiards is compared after the break (the cue ball reaches the rack at about 0.21 s).
    let plan = [
        ("gas1k", 5.0, 1.0, HORIZON_SECONDS),
        ("gas", 2.0, 0.5, HORIZON_SECONDS),
        ("billiards", 2.0, 1.0, 0.3),
        ("fast", 2.0, 0.5, HORIZON_SECONDS),
    ];
    for (name, seconds, quick_seconds, horizon) in plan {
        let config = crate::scene::Scene::load(&scenes_dir.join(format!("{name}.ron")))?;
        cases.push(Case {
            name: name.to_owned(),
            config,
            seconds: if quick { quick_seconds } else { seconds },
            horizon,
        });
    }
    Ok(cases)
}

/// The candidates `--solver auto` considers, cheapest first by design (the measurement decides).
pub const AUTO_CANDIDATES: [Solver; 6] = [
    Solver::Discrete,
    Solver::Substeps(2),
    Solver::Substeps(4),
    Solver::Substeps(8),
    Solver::Substeps(16),
    Solver::Swept,
];

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
/// of `config` (about [`HORIZON_SECONDS`], at most 60 steps), measured against `exact`; falls
/// back to `exact`, which meets any tolerance. Returns the choice and every measurement.
pub fn choose_solver(config: &CirclesConfig, tolerance: f64) -> (Solver, Vec<Calibration>) {
    let seconds = HORIZON_SECONDS.min(60.0 * config.dt);
    let case = Case {
        name: "calibration".into(),
        config: config.clone(),
        seconds,
        horizon: seconds,
    };
    let reference = trace(&case, Solver::Exact, config.dt);
    let mut measured: Vec<Calibration> = AUTO_CANDIDATES
        .iter()
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
        solver: Solver::Exact,
        error: 0.0,
        ms_per_step: reference.stepping.as_secs_f64() * 1e3 / reference.steps as f64,
    });
    let choice = measured
        .iter()
        .filter(|c| c.error <= tolerance)
        .min_by(|a, b| a.ms_per_step.total_cmp(&b.ms_per_step))
        .map_or(Solver::Exact, |c| c.solver);
    (choice, measured)
}
