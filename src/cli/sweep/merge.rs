//! `sweep merge`: every finished task's settings and report as one row of `merged.csv` and
//! `merged.json`, and the figure the spec asks for.

use std::path::Path;

use anyhow::{Context, bail};

use super::spec::{SweepFigure, TaskMeasure};
use super::{Plan, figures, pile_rows, trace_rows};
use crate::tools::accuracy::front::MEASURES;
use crate::tools::accuracy::piles::pile_table;
use crate::tools::accuracy::plot::AccuracyFigure;
use crate::tools::accuracy::report::to_fronts;
use crate::tools::io::{say, write_atomically, write_csv};

/// `sweep merge`: every task's settings and report as one row, into `merged.csv` and
/// `merged.json` in the sweep's folder; every task must be done.
pub fn merge(dir: &Path) -> anyhow::Result<()> {
    let plan = Plan::open(dir)?;
    let folder = &plan.folder;
    let missing: Vec<usize> = (0..plan.tasks.len())
        .filter(|&i| !folder.result(i).exists())
        .collect();
    if !missing.is_empty() {
        let shown: Vec<_> = missing.iter().take(20).collect();
        bail!(
            "{} of {} tasks have no result yet (tasks {shown:?}{}): `moving_circles sweep status \
             {}`",
            missing.len(),
            plan.tasks.len(),
            if missing.len() > shown.len() {
                ", ..."
            } else {
                ""
            },
            dir.display()
        );
    }
    let mut rows = Vec::new();
    for task in &plan.tasks {
        let report = plan.result(task.index)?;
        rows.push(serde_json::json!({ "task": task, "report": report }));
    }
    let json = serde_json::to_string_pretty(&rows)?;
    let csv = csv_of(&rows)?;
    let [csv_path, json_path] = ["merged.csv", "merged.json"].map(|name| dir.join(name));
    write_atomically(&csv_path, csv.as_bytes())
        .with_context(|| format!("writing {}", csv_path.display()))?;
    write_atomically(&json_path, json.as_bytes())
        .with_context(|| format!("writing {}", json_path.display()))?;
    say(format_args!(
        "merged {} tasks into {} and {}",
        rows.len(),
        csv_path.display(),
        json_path.display()
    ));
    match plan.spec.measure {
        // The study's own rows, and its figure with all five of its measures.
        TaskMeasure::Trace { .. } => {
            let rows = trace_rows(dir)?;
            write_csv(&rows, &dir.join("accuracy.csv"))?;
            if plan.spec.figure == Some(SweepFigure::Accuracy) {
                to_fronts(&rows, &MEASURES).lines().for_each(say);
                figures::draw_accuracy(&AccuracyFigure::study(&rows), dir)?;
            }
            return Ok(());
        }
        TaskMeasure::Pile => {
            let rows = pile_rows(dir)?;
            pile_table(&rows).lines().for_each(say);
            return write_csv(&rows, &dir.join("piles.csv"));
        }
        TaskMeasure::Report | TaskMeasure::Eos(_) => {}
    }
    match plan.spec.figure {
        Some(SweepFigure::Eos) => figures::eos(&rows, dir)?,
        Some(SweepFigure::Accuracy) => figures::accuracy(&rows, &plan.spec, dir)?,
        None => {}
    }
    Ok(())
}

/// The rows as CSV: the task's settings (`task`, `task_solver`, ...) then the report's fields,
/// arrays of numbers split into `name_0`, `name_1`, ..., other arrays as their items with
/// spaces between, objects as a column for each of their fields.
fn csv_of(rows: &[serde_json::Value]) -> anyhow::Result<String> {
    let flat: Vec<Vec<(String, String)>> = rows
        .iter()
        .map(|row| {
            let mut cells = flatten(&row["task"], "task_");
            if let Some(k) = cells.iter().position(|(k, _)| k == "task_index") {
                let (_, index) = cells.remove(k);
                cells.insert(0, ("task".into(), index));
            }
            cells.extend(flatten(&row["report"], ""));
            cells
        })
        .collect();
    let mut writer = csv::Writer::from_writer(Vec::new());
    if let Some(first) = flat.first() {
        writer.write_record(first.iter().map(|(k, _)| k))?;
    }
    for row in &flat {
        writer.write_record(row.iter().map(|(_, v)| v))?;
    }
    Ok(String::from_utf8(writer.into_inner()?)?)
}

/// An object's fields as `(column, text)`, each column named `prefix` and its key.
fn flatten(object: &serde_json::Value, prefix: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let Some(object) = object.as_object() else {
        return out;
    };
    for (key, value) in object {
        let key = format!("{prefix}{key}");
        match value {
            serde_json::Value::Array(items) if items.iter().all(|v| v.is_number()) => {
                for (k, item) in items.iter().enumerate() {
                    out.push((format!("{key}_{k}"), text_of(item)));
                }
            }
            serde_json::Value::Array(items) => {
                let words: Vec<String> = items.iter().map(text_of).collect();
                out.push((key.clone(), words.join(" ")));
            }
            serde_json::Value::Object(_) => out.extend(flatten(value, &format!("{key}_"))),
            _ => out.push((key, text_of(value))),
        }
    }
    out
}

/// A JSON value as a CSV cell.
fn text_of(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::Null => String::new(),
        serde_json::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}
