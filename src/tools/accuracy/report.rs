//! The study's results as text: the fixed-width table the command prints and the Pareto fronts
//! (the CSV, one column per [`Row`] field, is written by [`crate::tools::io::csv_text`]).

use super::front::{Measure, Panel, of_scene, scenes};
use super::measure::Row;

/// The study as a fixed-width table.
pub fn to_table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:<9} {:>6} {:<12} {:>6} {:>9} {:>9} {:>10} {:>9} {:>9} {:>6} {:>9} {:>8} {:>8}\n",
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
        "z err",
        "turn err"
    );
    for r in rows {
        out.push_str(&format!(
            "{:<9} {:>6} {:<12} {:>6.0} {:>9.3} {:>9.2e} {:>10.1e} {:>9.2e} {:>9.2e} {:>6} {:>+9.3} {:>8} {:>8}\n",
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
            r.turning_error.map(|t| format!("{t:+.3}")).unwrap_or_else(|| "-".into()),
        ));
    }
    out
}

/// Each scene's Pareto front per measure of `measures`, one line each: the settings,
/// cheapest first, that are more accurate than every cheaper one, ending at the reference.
/// What to pick for an error budget is the first setting within it.
pub fn to_fronts(rows: &[Row], measures: &[Measure]) -> String {
    let mut out = String::from(
        "Pareto fronts (cheapest first; ms of stepping per simulated second, then the error):\n",
    );
    for scene in scenes(rows) {
        let mine = of_scene(rows, scene);
        for measure in measures {
            let front: Vec<String> = Panel::new(&mine, measure)
                .front()
                .iter()
                .map(|p| format!("{} {:.3} ms ({:.2e})", p.label, p.cost, p.error))
                .collect();
            out.push_str(&format!(
                "{scene:<9} {:<27} {}\n",
                measure.title,
                front.join(" > ")
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tools::io::csv_text;

    #[test]
    fn the_csv_has_one_column_per_field_and_empty_cells_for_missing_values() {
        let row = Row {
            scene: "gas".into(),
            n: 3,
            solver: "substeps=4".into(),
            dt: 0.5,
            steps: 2,
            ms_per_step: 1.5,
            ms_per_sim_second: 3.0,
            horizon: 0.1,
            position_error: 1e-3,
            energy_drift: 0.0,
            momentum_drift: 0.0,
            max_penetration: 0.25,
            mean_penetration: 0.125,
            tunnelled: 1,
            escaped: 0,
            pair_collisions: 42,
            collision_error: -0.5,
            z: None,
            z_error: Some(0.01),
            speed_ks: 0.0,
            turning_error: None,
        };
        let csv = csv_text(&[row]).unwrap();
        let mut lines = csv.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let cells: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(header.len(), 21);
        assert_eq!(header.len(), cells.len());
        let cell = |name: &str| cells[header.iter().position(|&h| h == name).unwrap()];
        assert_eq!(cell("solver"), "substeps=4");
        assert_eq!(cell("pair_collisions"), "42");
        assert_eq!(cell("z"), "");
        assert_eq!(cell("z_error"), "0.01");
    }
}
