//! The figures `sweep merge` draws from the merged rows (each a task's settings and report):
//! the equation of state over seeds, and what accuracy costs.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde_json::Value;

use super::spec::SweepSpec;
use super::spec_rules::is_reference_dt;
use crate::base::config::Solver;
use crate::tools::accuracy::Row;
use crate::tools::accuracy::front::REPORT_MEASURES;
use crate::tools::accuracy::plot::AccuracyFigure;
use crate::tools::accuracy::report::to_fronts;
use crate::tools::eos::EosPoint;
use crate::tools::eos::plot::EosFigure;
use crate::tools::eos::theory::{henderson_z, liu_z};
use crate::tools::figure::{Figure, png, svg};
use crate::tools::io::{say, write_atomically};

/// The equation of state of the merged rows: for each area fraction, the mean of the tasks'
/// `z` and its standard error over them (the seeds), or the one task's point with its blocks'
/// error under the `eos` measure, drawn as the `eos` command draws its points, into
/// `eos.svg` and `eos.png` in `dir`.
pub(super) fn eos(rows: &[serde_json::Value], dir: &Path) -> anyhow::Result<()> {
    let mut by_fraction: Vec<(f64, Vec<&serde_json::Value>)> = Vec::new();
    for row in rows {
        let Some(phi) = row["task"]["area_fraction"].as_f64() else {
            continue;
        };
        match by_fraction.iter_mut().find(|(f, _)| *f == phi) {
            Some((_, group)) => group.push(&row["report"]),
            None => by_fraction.push((phi, vec![&row["report"]])),
        }
    }
    by_fraction.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut points = Vec::new();
    let mut bars = "standard error over seeds";
    for (phi, reports) in by_fraction {
        if let [one] = reports[..]
            && one.get("z_error").is_some()
        {
            bars = "block error bars";
            points
                .push(eos_point(one).with_context(|| format!("the point at area fraction {phi}"))?);
            continue;
        }
        let zs: Vec<f64> = reports.iter().filter_map(|r| r["z"].as_f64()).collect();
        if zs.is_empty() {
            bail!("no task at area fraction {phi} measured z (the report's `z`)");
        }
        let k = zs.len() as f64;
        let z = zs.iter().sum::<f64>() / k;
        let spread = zs.iter().map(|x| (x - z).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
        let sum = |field: &str| {
            reports
                .iter()
                .filter_map(|r| r[field].as_f64())
                .sum::<f64>()
        };
        let liu = liu_z(phi);
        let z_error = (spread / k).sqrt();
        say(format_args!(
            "area fraction {phi}: z {z:.5} ± {z_error:.5} over {} tasks (Liu {liu:.5})",
            zs.len()
        ));
        points.push(EosPoint {
            area_fraction: phi,
            n: (sum("n") / reports.len() as f64).round() as usize,
            z,
            z_error,
            henderson: henderson_z(phi),
            liu,
            vs_liu: z / liu - 1.0,
            blocks: zs.len(),
            collisions: (sum("pair_collisions") + sum("collisions")) as u64,
            sim_seconds: sum("sim_seconds"),
            speed_ks: f64::NAN,
            speed_ks_critical: f64::NAN,
            wall_seconds: sum("wall_seconds"),
        });
    }
    let solver = rows
        .first()
        .and_then(|row| row["report"]["solver"].as_str())
        .unwrap_or("exact");
    let bars = format!("{solver}, {bars}");
    let figure = EosFigure {
        points: &points,
        bars: &bars,
    };
    let [vector, picture] = draw(&figure, dir, "eos")?;
    say(format_args!(
        "drew the equation of state of {} area fractions into {} and {}",
        points.len(),
        vector.display(),
        picture.display()
    ));
    Ok(())
}

/// An `eos` task's result as the point it is; a number JSON could not hold (`null`) is not a
/// number.
pub(crate) fn eos_point(json: &Value) -> anyhow::Result<EosPoint> {
    let number = |field: &str| json[field].as_f64().unwrap_or(f64::NAN);
    let count = |field: &str| {
        json[field]
            .as_u64()
            .with_context(|| format!("`{field}` is not a count"))
    };
    Ok(EosPoint {
        area_fraction: json["area_fraction"]
            .as_f64()
            .context("`area_fraction` is not a number")?,
        n: count("n")? as usize,
        z: number("z"),
        z_error: number("z_error"),
        henderson: number("henderson"),
        liu: number("liu"),
        vs_liu: number("vs_liu"),
        blocks: count("blocks")? as usize,
        collisions: count("collisions")?,
        sim_seconds: number("sim_seconds"),
        speed_ks: number("speed_ks"),
        speed_ks_critical: number("speed_ks_critical"),
        wall_seconds: number("wall_seconds"),
    })
}

/// What accuracy costs, from the merged rows: [`accuracy_rows`] drawn as the accuracy study
/// draws its figure, over the measures a report carries, into `accuracy.svg` and
/// `accuracy.png` in `dir`, with each Pareto front printed.
pub(super) fn accuracy(rows: &[Value], spec: &SweepSpec, dir: &Path) -> anyhow::Result<()> {
    let stem = spec
        .scene
        .as_deref()
        .or(spec.particles.as_deref())
        .and_then(Path::file_stem)
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let rows = accuracy_rows(rows, &stem)?;
    let seeds = spec
        .axes
        .iter()
        .find(|a| a.name() == "seed")
        .map_or(1, |a| a.len());
    let figure = AccuracyFigure {
        rows: &rows,
        measures: &REPORT_MEASURES,
        note: format!(
            "Each point is the mean over {seeds} seed(s) of a setting's cost and of the size of \
             its error against exact at 60 Hz with the same seed. 0 on an axis: no error at all."
        ),
    };
    to_fronts(&rows, &REPORT_MEASURES).lines().for_each(say);
    draw_accuracy(&figure, dir)
}

/// Draws `figure` into `accuracy.svg` and `accuracy.png` in `dir`, and says so.
pub(super) fn draw_accuracy(figure: &AccuracyFigure, dir: &Path) -> anyhow::Result<()> {
    let [vector, picture] = draw(figure, dir, "accuracy")?;
    say(format_args!(
        "drew what accuracy costs into {} and {}",
        vector.display(),
        picture.display()
    ));
    Ok(())
}

/// The merged rows as the accuracy study's rows: one for each case (a setting of the axes
/// other than solver, step and seed; named by what varies between cases, or `stem` when
/// only one) and setting of solver and step, each error against the `exact` task at 60 Hz of
/// the same case and seed, and each field the mean over the seeds (of an error's size). What
/// a report does not hold (position error, tunnelling, speed distribution, turning) is not a
/// number, or none.
pub(super) fn accuracy_rows(rows: &[Value], stem: &str) -> anyhow::Result<Vec<Row>> {
    // A case is the task's settings but its index, solver, step, seed and own scene file
    // (named after the fields it sets, which stay in the key).
    let case_of = |task: &Value| -> BTreeMap<String, Value> {
        let mut key: BTreeMap<String, Value> = task
            .as_object()
            .map(|o| o.clone().into_iter().collect())
            .unwrap_or_default();
        for name in ["index", "solver", "dt", "seed", "scene"] {
            key.remove(name);
        }
        key
    };
    let number = |row: &Value, field: &str| -> anyhow::Result<f64> {
        row["report"][field].as_f64().with_context(|| {
            format!(
                "task {}: its report has no number `{field}`",
                row["task"]["index"]
            )
        })
    };
    let setting_of = |row: &Value| -> anyhow::Result<(String, f64)> {
        let solver = row["report"]["solver"].as_str().with_context(|| {
            format!("task {}: its report names no solver", row["task"]["index"])
        })?;
        Ok((solver.to_owned(), number(row, "dt")?))
    };
    let exact = Solver::REFERENCE.to_string();
    let mut cases: Vec<BTreeMap<String, Value>> = Vec::new();
    // (case, solver, step) -> the rows of each seed.
    type Setting = (usize, String, f64);
    let mut groups: Vec<(Setting, Vec<&Value>)> = Vec::new();
    for row in rows {
        let case = case_of(&row["task"]);
        let c = match cases.iter().position(|k| *k == case) {
            Some(c) => c,
            None => {
                cases.push(case);
                cases.len() - 1
            }
        };
        let (solver, dt) = setting_of(row)?;
        let key = (c, solver, dt);
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, members)) => members.push(row),
            None => groups.push((key, vec![row])),
        }
    }
    let names = case_names(&cases, stem);
    let mut out = Vec::new();
    for ((c, solver, dt), members) in &groups {
        let mut sums = [0.0; 8];
        let mut z_errors = Vec::new();
        let mut zs = Vec::new();
        for row in members {
            let seed = &row["task"]["seed"];
            let reference = groups
                .iter()
                .find(|((rc, rs, rdt), _)| rc == c && *rs == exact && is_reference_dt(*rdt))
                .and_then(|(_, refs)| refs.iter().find(|r| r["task"]["seed"] == *seed))
                .with_context(|| {
                    format!(
                        "task {}: the accuracy figure compares it with the `{exact}` task at \
                         60 Hz of the same seed and settings, and the sweep has none",
                        row["task"]["index"]
                    )
                })?;
            let collisions = number(row, "pair_collisions")?;
            let reference_collisions = number(reference, "pair_collisions")?;
            let sim_seconds = number(row, "sim_seconds")?;
            let values = [
                number(row, "wall_seconds")? * 1e3 / sim_seconds,
                number(row, "wall_seconds")? * 1e3 / number(row, "steps")?,
                relative_change(reference_collisions, collisions).abs(),
                number(row, "max_penetration")?,
                number(row, "mean_penetration")?,
                number(row, "energy_drift")?,
                number(row, "n")?,
                collisions,
            ];
            for (sum, value) in sums.iter_mut().zip(values) {
                *sum += value;
            }
            if let (Some(z), Some(zr)) = (
                row["report"]["z"].as_f64(),
                reference["report"]["z"].as_f64(),
            ) {
                zs.push(z);
                z_errors.push(((z - zr) / zr).abs());
            }
        }
        let k = members.len() as f64;
        let mean = |v: &[f64]| (v.len() == members.len()).then(|| v.iter().sum::<f64>() / k);
        let first = members[0];
        out.push(Row {
            scene: names[*c].clone(),
            n: (sums[6] / k).round() as usize,
            solver: solver.clone(),
            dt: *dt,
            steps: number(first, "steps")? as u64,
            ms_per_step: sums[1] / k,
            ms_per_sim_second: sums[0] / k,
            horizon: f64::NAN,
            position_error: f64::NAN,
            energy_drift: sums[5] / k,
            momentum_drift: f64::NAN,
            max_penetration: sums[3] / k,
            mean_penetration: sums[4] / k,
            tunnelled: 0,
            escaped: 0,
            pair_collisions: (sums[7] / k).round() as u64,
            collision_error: sums[2] / k,
            z: mean(&zs),
            z_error: mean(&z_errors),
            speed_ks: f64::NAN,
            turning_error: None,
        });
    }
    Ok(out)
}

/// `(value - reference) / reference`, or the change itself when the reference is 0.
fn relative_change(reference: f64, value: f64) -> f64 {
    if reference == 0.0 {
        value - reference
    } else {
        (value - reference) / reference
    }
}

/// Each case's name: the settings that differ between cases (`area_fraction 0.3`,
/// `effects.restitution 0.9`), or `stem` when there is one case.
fn case_names(cases: &[BTreeMap<String, Value>], stem: &str) -> Vec<String> {
    let flat: Vec<BTreeMap<String, String>> = cases
        .iter()
        .map(|case| {
            let mut out = BTreeMap::new();
            for (key, value) in case {
                match value {
                    Value::Object(fields) => {
                        for (path, v) in fields {
                            out.insert(path.clone(), v.to_string());
                        }
                    }
                    other => {
                        out.insert(key.clone(), other.to_string());
                    }
                }
            }
            out
        })
        .collect();
    flat.iter()
        .map(|case| {
            let varying: Vec<String> = case
                .iter()
                .filter(|(key, value)| flat.iter().any(|other| other.get(*key) != Some(*value)))
                .map(|(key, value)| format!("{key} {value}"))
                .collect();
            if varying.is_empty() {
                stem.to_owned()
            } else {
                varying.join(", ")
            }
        })
        .collect()
}

/// Writes `figure` as `<stem>.svg` and `<stem>.png` in `dir`, each atomically; returns their
/// paths.
fn draw(figure: &impl Figure, dir: &Path, stem: &str) -> anyhow::Result<[PathBuf; 2]> {
    let [vector, picture] = ["svg", "png"].map(|ext| dir.join(format!("{stem}.{ext}")));
    let drawing = svg(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", vector.display()))?;
    write_atomically(&vector, drawing.as_bytes())
        .with_context(|| format!("writing {}", vector.display()))?;
    let bytes = png(figure).map_err(|e| anyhow::anyhow!("drawing {}: {e}", picture.display()))?;
    write_atomically(&picture, &bytes).with_context(|| format!("writing {}", picture.display()))?;
    Ok([vector, picture])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A merged row: task `index` of `solver` at `dt` with `seed`, `collisions` in its report.
    fn row(index: usize, solver: &str, dt: f64, seed: u64, collisions: u64) -> Value {
        serde_json::json!({
            "task": { "index": index, "solver": solver, "dt": dt, "seed": seed,
                      "length": { "steps": 10 } },
            "report": { "solver": solver, "dt": dt, "n": 50, "steps": 10,
                        "sim_seconds": 10.0 * dt, "wall_seconds": 0.01 * index as f64 + 0.01,
                        "pair_collisions": collisions, "max_penetration": 0.0,
                        "mean_penetration": 0.0, "energy_drift": 0.0, "z": null },
        })
    }

    #[test]
    fn each_seed_is_compared_with_the_reference_of_its_own_seed() {
        let rows = [
            row(0, "exact", 1.0 / 60.0, 1, 100),
            row(1, "exact", 1.0 / 60.0, 2, 200),
            row(2, "discrete", 1.0 / 30.0, 1, 110),
            row(3, "discrete", 1.0 / 30.0, 2, 180),
        ];
        let rows = accuracy_rows(&rows, "gas").unwrap();
        assert_eq!(rows.len(), 2);
        let discrete = rows.iter().find(|r| r.solver == "discrete").unwrap();
        // +10 % against seed 1's 100 and -10 % against seed 2's 200: 0.1 in size each (against
        // seed 1's alone the second would be 0.8).
        assert!(
            (discrete.collision_error - 0.1).abs() < 1e-12,
            "{}",
            discrete.collision_error
        );
        assert_eq!(discrete.scene, "gas");
        let exact = rows.iter().find(|r| r.solver == "exact").unwrap();
        assert_eq!(exact.collision_error, 0.0);
        // The cost is the mean over the seeds: (10 + 20) ms... of tasks 0 and 1.
        assert!(
            (exact.ms_per_step - 1.5).abs() < 1e-12,
            "{}",
            exact.ms_per_step
        );
    }

    #[test]
    fn a_setting_without_its_seeds_reference_is_refused_naming_the_task() {
        let rows = [
            row(0, "exact", 1.0 / 60.0, 1, 100),
            row(1, "discrete", 1.0 / 30.0, 2, 180),
        ];
        let error = format!("{:#}", accuracy_rows(&rows, "gas").unwrap_err());
        assert!(
            error.contains("task 1: the accuracy figure compares"),
            "{error}"
        );
    }

    #[test]
    fn cases_are_named_by_what_differs_between_them() {
        let mut a = row(0, "exact", 1.0 / 60.0, 1, 100);
        let mut b = row(1, "exact", 1.0 / 60.0, 1, 100);
        a["task"]["fields"] = serde_json::json!({ "effects.restitution": 0.5 });
        b["task"]["fields"] = serde_json::json!({ "effects.restitution": 1.0 });
        let rows = accuracy_rows(&[a, b], "gas").unwrap();
        let names: Vec<&str> = rows.iter().map(|r| r.scene.as_str()).collect();
        assert_eq!(
            names,
            ["effects.restitution 0.5", "effects.restitution 1.0"]
        );
    }
}
