//! The accuracy study's runs as sweep tasks: a `trace` task runs the scene under its solver and
//! step and keeps its trace beside its report, a `pile` task measures a pile run; once all are
//! done, [`trace_rows`] compares each trace with the `exact` task's at 60 Hz as the study does,
//! and [`pile_rows`] reads the pile rows back.

use std::io::Read;
use std::path::Path;

use anyhow::{Context, bail};

use super::Plan;
use super::spec::{SpecLength, Task, TaskMeasure};
use super::spec_rules::is_reference_dt;
use crate::base::config::Solver;
use crate::cli::run::Finished;
use crate::tools::accuracy::piles::{PileRow, measure_pile};
use crate::tools::accuracy::{Case, Row, Trace, compare, trace};
use crate::tools::io::write_atomically;
use crate::tools::scene::Scene;

/// The largest trace read back: two states of a million circles are about 140 MB.
const MAX_TRACE_BYTES: u64 = 1 << 30;

/// The study's case of the sweep (its scene, named by its file, run for the spec's seconds,
/// compared at `horizon`), and `task`'s solver and step (the scene's where no axis sets them).
fn case_of(plan: &Plan, task: &Task, horizon: f64) -> anyhow::Result<(Case, Solver, f64)> {
    let (Some(scene), Some(SpecLength::Seconds(seconds))) = (&plan.spec.scene, task.length) else {
        bail!("a study task has a scene and runs for a time");
    };
    let config = Scene::load(scene)?;
    let solver = match &task.solver {
        Some(name) => name.parse().map_err(|e| anyhow::anyhow!("solver: {e}"))?,
        None => config.solver,
    };
    let dt = task.dt.unwrap_or(config.dt);
    let name = scene
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    let case = Case {
        name,
        config,
        seconds,
        horizon,
    };
    Ok((case, solver, dt))
}

/// Runs `task` as the study runs a setting: its trace into `work/I.trace`, its report into
/// `work/I.report.json` (the task's end puts both in place).
pub(super) fn trace_task(plan: &Plan, task: &Task, horizon: f64) -> anyhow::Result<Finished> {
    crate::cli::run::set_threads(Some(1));
    let (case, solver, dt) = case_of(plan, task, horizon)?;
    let run = trace(&case, solver, dt);
    let folder = &plan.folder;
    let path = folder.trace_under_way(task.index);
    let bytes = postcard::to_stdvec(&run).context("the trace")?;
    write_atomically(&path, &bytes).with_context(|| format!("writing {}", path.display()))?;
    let path = folder.report(task.index);
    let text = serde_json::to_string_pretty(&run.report).context("the report as JSON")?;
    write_atomically(&path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(Finished::Completed)
}

/// Measures `task` as the study measures a pile setting, into `work/I.report.json`.
pub(super) fn pile_task(plan: &Plan, task: &Task) -> anyhow::Result<Finished> {
    crate::cli::run::set_threads(Some(1));
    let (mut case, solver, dt) = case_of(plan, task, 0.0)?;
    case.horizon = case.seconds;
    let row = measure_pile(&case, solver, dt);
    let path = plan.folder.report(task.index);
    let text = serde_json::to_string_pretty(&row).context("the row as JSON")?;
    write_atomically(&path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(Finished::Completed)
}

/// The study's rows of the `trace` sweep in `dir`, in task order: each task's trace compared
/// with that of the `exact` task at 60 Hz; every task must be done.
pub(crate) fn trace_rows(dir: &Path) -> anyhow::Result<Vec<Row>> {
    let plan = Plan::open(dir)?;
    let TaskMeasure::Trace { horizon } = plan.spec.measure else {
        bail!("{}: not a sweep of the `trace` measure", dir.display());
    };
    let Some(first) = plan.tasks.first() else {
        return Ok(Vec::new());
    };
    let (case, _, _) = case_of(&plan, first, horizon)?;
    let read = |task: &Task| -> anyhow::Result<Trace> {
        let path = plan.folder.trace(task.index);
        let mut bytes = Vec::new();
        std::fs::File::open(&path)
            .with_context(|| format!("{}", path.display()))?
            .take(MAX_TRACE_BYTES)
            .read_to_end(&mut bytes)
            .with_context(|| format!("{}", path.display()))?;
        postcard::from_bytes(&bytes).with_context(|| {
            format!(
                "{}: not a trace this version reads (one from another build?): remove {} and \
                 run the sweep again",
                path.display(),
                dir.display()
            )
        })
    };
    // The reference first; then one trace at a time, so that a big scene's traces are never
    // all in memory at once.
    let reference = plan
        .tasks
        .iter()
        .map(|task| read(task).map(|trace| (task, trace)))
        .find(|read| {
            read.as_ref().map_or(true, |(_, t)| {
                t.solver == Solver::REFERENCE && is_reference_dt(t.dt)
            })
        })
        .transpose()?
        .map(|(_, trace)| trace)
        .with_context(|| {
            format!(
                "{}: the study compares each run with `exact` at 60 Hz, and the sweep has no \
                 such task",
                dir.display()
            )
        })?;
    plan.tasks
        .iter()
        .map(|task| Ok(compare(&case, &read(task)?, &reference)))
        .collect()
}

/// The pile rows of the `pile` sweep in `dir`, in task order; every task must be done.
pub(crate) fn pile_rows(dir: &Path) -> anyhow::Result<Vec<PileRow>> {
    let plan = Plan::open(dir)?;
    if plan.spec.measure != TaskMeasure::Pile {
        bail!("{}: not a sweep of the `pile` measure", dir.display());
    }
    plan.tasks
        .iter()
        .map(|task| {
            serde_json::from_value(plan.result(task.index)?).with_context(|| {
                format!(
                    "{}: not a pile row",
                    plan.folder.result(task.index).display()
                )
            })
        })
        .collect()
}
