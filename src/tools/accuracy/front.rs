//! What the figure plots and what a reader takes from it: the error measures that separate the
//! solvers ([`MEASURES`]) and, for each, the Pareto front of cost against error
//! ([`pareto_front`]): the settings that no cheaper setting matches.

use super::measure::{REFERENCE_DT, Row};
use crate::base::config::Solver;

/// One error measure the figure plots against cost.
#[derive(Clone, Copy, Debug)]
pub struct Measure {
    /// Panel title.
    pub title: &'static str,
    /// What the value is, for the axis.
    pub unit: &'static str,
    /// The row's value, absolute and never negative; `None` when the scene has none.
    pub value: fn(&Row) -> Option<f64>,
}

/// The measures that separate the solvers, in the figure's column order. Energy drift is left
/// out: it is at rounding for every solver in the study's elastic scenes.
pub const MEASURES: [Measure; 5] = [
    Measure {
        title: "collisions missed or added",
        unit: "|count - exact| / exact",
        value: |r| Some(r.collision_error.abs()),
    },
    Measure {
        title: "pressure error",
        unit: "|z - exact| / exact",
        value: |r| r.z_error.map(f64::abs),
    },
    Measure {
        title: "deepest overlap",
        unit: "smaller radii",
        value: |r| Some(r.max_penetration),
    },
    Measure {
        title: "pairs tunnelled",
        unit: "pairs",
        value: |r| Some(r.tunnelled as f64),
    },
    Measure {
        title: "position error",
        unit: "mean radii, at the horizon",
        value: |r| Some(r.position_error),
    },
];

/// The measures a run's report carries (no trajectory needed), the first three of
/// [`MEASURES`]: what a sweep's merge can draw.
pub const REPORT_MEASURES: [Measure; 3] = [MEASURES[0], MEASURES[1], MEASURES[2]];

/// Indices of the points on the Pareto front of `(cost, error)`, cheapest first: each has a
/// smaller error than every cheaper point. Of equally cheap points only the most accurate
/// can be on it. Points with a cost or error that is not a number are never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pa.0.total_cmp(&pb.0).then(pa.1.total_cmp(&pb.1))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].1 < best {
            best = points[i].1;
            front.push(i);
        }
    }
    front
}

/// One scene's rows seen through one measure: the reference, and every other row with its
/// value (rows the measure has no value for are left out).
pub struct Panel<'a> {
    /// `exact` at [`REFERENCE_DT`]: the run the others are compared with (its error is 0).
    pub reference: Option<&'a Row>,
    /// The other rows and their values.
    pub points: Vec<(&'a Row, f64)>,
}

/// A setting on a front.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontPoint {
    /// The setting, e.g. `substeps=4 at 60 Hz`.
    pub label: String,
    /// Its [`cost`].
    pub cost: f64,
    /// Its error (0 for the reference).
    pub error: f64,
}

impl<'a> Panel<'a> {
    /// Splits one scene's `rows` into the reference and the others' values of `measure`.
    pub fn new(rows: &[&'a Row], measure: &Measure) -> Self {
        let is_reference = |r: &Row| {
            r.solver == Solver::REFERENCE.to_string()
                && rate(r) == (1.0 / REFERENCE_DT).round() as u32
        };
        Panel {
            reference: rows.iter().copied().find(|r| is_reference(r)),
            points: rows
                .iter()
                .filter(|r| !is_reference(r))
                .filter_map(|r| Some((*r, (measure.value)(r)?)))
                .collect(),
        }
    }

    /// The front, cheapest first, the reference included at error 0.
    pub fn front(&self) -> Vec<FrontPoint> {
        let mut all: Vec<FrontPoint> = self
            .points
            .iter()
            .map(|(r, error)| FrontPoint {
                label: setting(r),
                cost: cost(r),
                error: *error,
            })
            .collect();
        all.extend(self.reference.map(|r| FrontPoint {
            label: format!("{} (reference)", setting(r)),
            cost: cost(r),
            error: 0.0,
        }));
        let costs: Vec<(f64, f64)> = all.iter().map(|p| (p.cost, p.error)).collect();
        pareto_front(&costs)
            .into_iter()
            .map(|i| all[i].clone())
            .collect()
    }
}

/// The scenes in `rows`, in order of first appearance.
pub fn scenes(rows: &[Row]) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    for r in rows {
        if !names.contains(&r.scene.as_str()) {
            names.push(&r.scene);
        }
    }
    names
}

/// The rows of one scene.
pub fn of_scene<'a>(rows: &'a [Row], scene: &str) -> Vec<&'a Row> {
    rows.iter().filter(|r| r.scene == scene).collect()
}

/// What a setting costs, to compare settings with different steps: ms of stepping per
/// simulated second (the share of a core a real-time run of it takes, in thousandths).
pub fn cost(row: &Row) -> f64 {
    row.ms_per_sim_second
}

/// A row's setting as the figure and the front name it: `substeps=4 at 60 Hz`.
pub fn setting(row: &Row) -> String {
    format!("{} at {} Hz", row.solver, rate(row))
}

/// A row's steps per second, rounded: 30, 60 or 120 in the study.
pub fn rate(row: &Row) -> u32 {
    (1.0 / row.dt).round() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_only_points_no_cheaper_point_matches() {
        let points = [
            (1.0, 0.5),
            (2.0, 0.6), // dearer and worse than the first
            (3.0, 0.1),
            (0.5, 0.9),
            (3.0, 0.05), // as cheap as the third, more accurate: it alone is kept
            (4.0, 0.05), // no better than the fifth
            (9.0, 0.0),
            (f64::NAN, 0.0),
        ];
        assert_eq!(pareto_front(&points), vec![3, 0, 4, 6]);
        assert!(pareto_front(&[]).is_empty());
    }

    fn row(solver: &str, hz: f64, cost: f64, tunnelled: u64, z_error: Option<f64>) -> Row {
        Row {
            scene: "gas".into(),
            n: 10,
            solver: solver.into(),
            dt: 1.0 / hz,
            steps: 10,
            ms_per_step: cost / hz,
            ms_per_sim_second: cost,
            horizon: 0.1,
            position_error: 0.0,
            energy_drift: 0.0,
            momentum_drift: 0.0,
            max_penetration: 0.0,
            mean_penetration: 0.0,
            tunnelled,
            escaped: 0,
            pair_collisions: 100,
            collision_error: 0.0,
            z: None,
            z_error,
            speed_ks: 0.0,
            turning_error: None,
        }
    }

    #[test]
    fn the_reference_is_no_data_point_and_ends_every_front_at_zero() {
        let rows = [
            row("discrete", 30.0, 1.0, 40, Some(-0.1)),
            row("discrete", 60.0, 2.0, 10, None),
            row("exact", 30.0, 2.5, 0, Some(1e-9)),
            row("exact", 60.0, 3.0, 0, Some(0.0)),
            row("substeps=16", 60.0, 5.0, 1, Some(0.01)),
        ];
        let rows: Vec<&Row> = rows.iter().collect();
        let tunnelled = Panel::new(&rows, &MEASURES[3]);
        assert_eq!(tunnelled.reference.unwrap().ms_per_sim_second, 3.0);
        assert_eq!(tunnelled.points.len(), 4, "every row but the reference");
        let labels =
            |panel: &Panel| -> Vec<String> { panel.front().into_iter().map(|p| p.label).collect() };
        // exact at 30 Hz tunnels nothing and is cheaper than the reference, so the front ends
        // there and the reference is not on it.
        assert_eq!(
            labels(&tunnelled),
            ["discrete at 30 Hz", "discrete at 60 Hz", "exact at 30 Hz"]
        );
        // The pressure error is absolute, and a row without one is left out.
        let pressure = Panel::new(&rows, &MEASURES[1]);
        assert_eq!(pressure.points.len(), 3);
        assert_eq!(pressure.points[0].1, 0.1);
        assert_eq!(
            labels(&pressure),
            [
                "discrete at 30 Hz",
                "exact at 30 Hz",
                "exact at 60 Hz (reference)"
            ]
        );
        assert_eq!(pressure.front().last().unwrap().error, 0.0);
    }
}
