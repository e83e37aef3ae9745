//! `moving_circles sweep`: a grid of headless runs ([`spec::SweepSpec`]) planned into a folder,
//! run task by task (`sweep task`, by a Slurm job array or by `sweep run` on this machine's
//! cores), watched (`sweep status`) and merged (`sweep merge`).
//!
//! The folder holds everything: `spec.ron` (the spec, its scene made absolute; written last,
//! so a folder with one holds a whole plan), `tasks.jsonl` (one task a line), `sweep.sbatch`
//! (the Slurm array), `work/` (a running task's checkpoint and report), `results/` (each
//! finished task's report, put in place by a rename: a task has a result whole or none),
//! `failed/` (why a task failed) and `logs/`. Each task is a `run` of the scene with the
//! task's settings, so a task stopped by a signal writes a checkpoint and the next try goes on
//! from it to the same bits.

mod field_axis;
mod fields;
mod figures;
mod local;
mod measure;
mod merge;
mod slurm;
pub mod spec;
mod spec_rules;
mod study;
mod task;

pub use local::run;
pub use merge::merge;
pub(crate) use study::{pile_rows, trace_rows};

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::cli::run::{Finished, Input, Length, RunOptions, SolverChoice};
use crate::tools::checkpoint::Checkpoint;
use crate::tools::eos::{EosOptions, measure};
use crate::tools::io::{read_limited, say, write_atomically};
use crate::tools::scene::Scene;
use spec::{EosMeasure, SpecLength, SweepSpec, Task, TaskMeasure};

/// The files and folders of a planned sweep.
struct Folder {
    dir: PathBuf,
}

impl Folder {
    fn spec(&self) -> PathBuf {
        self.dir.join("spec.ron")
    }
    fn tasks(&self) -> PathBuf {
        self.dir.join("tasks.jsonl")
    }
    fn script(&self) -> PathBuf {
        self.dir.join("sweep.sbatch")
    }
    fn result(&self, index: usize) -> PathBuf {
        self.dir.join("results").join(format!("{index}.json"))
    }
    fn failure(&self, index: usize) -> PathBuf {
        self.dir.join("failed").join(format!("{index}.txt"))
    }
    fn checkpoint(&self, index: usize) -> PathBuf {
        self.dir.join("work").join(format!("{index}.checkpoint"))
    }
    fn report(&self, index: usize) -> PathBuf {
        self.dir.join("work").join(format!("{index}.report.json"))
    }
    fn dump(&self, index: usize) -> PathBuf {
        self.dir.join("work").join(format!("{index}.dump.txt"))
    }
    fn kept_dump(&self, index: usize) -> PathBuf {
        self.dir.join("results").join(format!("{index}.dump.txt"))
    }
    fn trace(&self, index: usize) -> PathBuf {
        self.dir.join("results").join(format!("{index}.trace"))
    }
    fn trace_under_way(&self, index: usize) -> PathBuf {
        self.dir.join("work").join(format!("{index}.trace"))
    }
    fn log(&self, index: usize) -> PathBuf {
        self.dir.join("logs").join(format!("{index}.log"))
    }
}

/// A planned sweep, read back from its folder.
struct Plan {
    folder: Folder,
    spec: SweepSpec,
    tasks: Vec<Task>,
}

impl Plan {
    /// Reads the plan in `dir`.
    fn open(dir: &Path) -> anyhow::Result<Self> {
        let folder = Folder {
            dir: dir.to_owned(),
        };
        let spec_path = folder.spec();
        if !spec_path.exists() {
            bail!(
                "{} holds no planned sweep (no spec.ron): plan one with `moving_circles sweep \
                 plan SPEC --out {}`",
                dir.display(),
                dir.display()
            );
        }
        let spec = SweepSpec::read(&spec_path).map_err(anyhow::Error::msg)?;
        // The task list is the spec's, expanded again: the file is for people and Slurm's
        // logs, and cannot disagree with the spec it came from.
        let mut tasks = spec.tasks();
        fields::name_scenes(&mut tasks);
        Ok(Self {
            folder,
            spec,
            tasks,
        })
    }

    /// Task `index`'s result: a JSON object (a report, a point, a row).
    fn result(&self, index: usize) -> anyhow::Result<serde_json::Value> {
        let path = self.folder.result(index);
        let file = std::fs::File::open(&path).with_context(|| format!("{}", path.display()))?;
        let text = read_limited(file, 1 << 20).map_err(anyhow::Error::msg)?;
        serde_json::from_str(&text)
            .ok()
            .filter(serde_json::Value::is_object)
            .with_context(|| format!("{}: not a task's result", path.display()))
    }
}

/// `sweep plan`: checks the spec and its scene, and writes the plan into `out`.
pub fn plan(spec_path: &Path, out: &Path) -> anyhow::Result<()> {
    let mut spec = SweepSpec::read(spec_path).map_err(anyhow::Error::msg)?;
    let folder = spec_path.parent().unwrap_or(Path::new("."));
    let absolute = |field: &str, relative: &Path| {
        let path = folder.join(relative);
        path.canonicalize()
            .with_context(|| format!("{}: {field}: {}", spec_path.display(), path.display()))
    };
    spec.scene = spec.scene.map(|s| absolute("scene", &s)).transpose()?;
    spec.particles = spec
        .particles
        .map(|p| absolute("particles", &p))
        .transpose()?;
    let tasks = plan_spec(&spec, &spec_path.display().to_string(), out)?;
    if let Some(tasks) = tasks {
        say(format_args!("planned {tasks} tasks in {}", out.display()));
        say(format_args!(
            "  here:     moving_circles sweep run {} --jobs 2",
            out.display()
        ));
        say(format_args!(
            "  on Slurm: sbatch {}",
            Folder {
                dir: out.to_owned()
            }
            .script()
            .display()
        ));
    }
    Ok(())
}

/// Writes the plan of `spec` (checked, its scene's path absolute; `origin` names it in
/// errors) into `out`: its number of tasks, or `None` when `out` holds this plan already.
pub(crate) fn plan_spec(
    spec: &SweepSpec,
    origin: &str,
    out: &Path,
) -> anyhow::Result<Option<usize>> {
    // The scene is checked now, not in each of a thousand tasks; read once, it is also the
    // base of the scenes `field` axes set.
    let base = match &spec.scene {
        Some(scene) => {
            let base = Scene::read(scene)?;
            let config = base.to_config(&scene.display().to_string())?;
            spec.check_scene_step(config.dt)
                .map_err(|e| anyhow::anyhow!("{origin}: {e}"))?;
            Some(base)
        }
        None => None,
    };
    if let Some(path) = &spec.particles {
        // Read once now, like a scene, not found wanting in each task.
        crate::tools::scene::particles::read_until(
            path,
            spec.boundary.unwrap_or_default(),
            || false,
        )?;
    }
    // Written as a spec is read: `scene: "..."`, `eos(n: 4096)`.
    let extensions = ron::extensions::Extensions::IMPLICIT_SOME
        | ron::extensions::Extensions::UNWRAP_VARIANT_NEWTYPES;
    let pretty = ron::ser::PrettyConfig::default().extensions(extensions);
    let text = ron::ser::to_string_pretty(spec, pretty).context("writing the spec")?;
    let folder = Folder {
        dir: out.to_owned(),
    };
    if folder.spec().exists() {
        // Compared as specs, not as text: a plan written by another version in other words
        // is the same plan.
        let planned = SweepSpec::read(&folder.spec()).map_err(anyhow::Error::msg)?;
        if planned == *spec {
            say(format_args!(
                "{} holds this sweep's plan already",
                out.display()
            ));
            return Ok(None);
        }
        bail!(
            "{} holds another sweep's plan (its spec.ron differs from {origin}): use another \
             folder, or remove that one",
            out.display(),
        );
    }
    for sub in ["results", "failed", "work", "logs", "scenes"] {
        let path = out.join(sub);
        std::fs::create_dir_all(&path).with_context(|| format!("creating {}", path.display()))?;
    }
    let mut tasks = spec.tasks();
    if let Some(base) = &base
        && tasks.iter().any(|t| !t.fields.is_empty())
    {
        fields::write_scenes(base, &mut tasks, out).with_context(|| origin.to_owned())?;
    }
    let mut lines = String::new();
    for task in &tasks {
        lines.push_str(&serde_json::to_string(task).context("a task as JSON")?);
        lines.push('\n');
    }
    write_atomically(&folder.tasks(), lines.as_bytes())
        .with_context(|| format!("writing {}", folder.tasks().display()))?;
    let dir = out
        .canonicalize()
        .with_context(|| format!("{}", out.display()))?;
    let script = slurm::batch_script(&spec.slurm, tasks.len(), &dir)?;
    write_atomically(&folder.script(), script.as_bytes())
        .with_context(|| format!("writing {}", folder.script().display()))?;
    // Last: a folder with a spec holds a whole plan.
    write_atomically(&folder.spec(), text.as_bytes())
        .with_context(|| format!("writing {}", folder.spec().display()))?;
    Ok(Some(tasks.len()))
}

/// `sweep task`: runs task `index` (from `SLURM_ARRAY_TASK_ID` when `None`), or does nothing
/// if it has its result; goes on from its checkpoint if an earlier try left one.
pub fn task(dir: &Path, index: Option<usize>) -> anyhow::Result<Finished> {
    let plan = Plan::open(dir)?;
    let index = match index {
        Some(index) => index,
        None => std::env::var("SLURM_ARRAY_TASK_ID")
            .context("no --index and no SLURM_ARRAY_TASK_ID")?
            .parse()
            .context("SLURM_ARRAY_TASK_ID")?,
    };
    let Some(task) = plan.tasks.get(index) else {
        bail!(
            "task {index}: the sweep in {} has tasks 0 to {}",
            dir.display(),
            plan.tasks.len() - 1
        );
    };
    let folder = &plan.folder;
    let result = folder.result(index);
    if result.exists() {
        say(format_args!(
            "task {index} is done already: {}",
            result.display()
        ));
        return Ok(Finished::Completed);
    }
    let outcome = match &plan.spec.measure {
        TaskMeasure::Report => run_task(&plan, task),
        TaskMeasure::Eos(eos) => eos_task(folder, eos, task),
        TaskMeasure::Trace { horizon } => study::trace_task(&plan, task, *horizon),
        TaskMeasure::Pile => study::pile_task(&plan, task),
    };
    let outcome = outcome.and_then(|finished| {
        if finished == Finished::Completed {
            // The dump and the trace first: a task with its report in `results/` has
            // everything there.
            if plan.spec.dump {
                let kept = folder.kept_dump(index);
                std::fs::rename(folder.dump(index), &kept)
                    .with_context(|| format!("putting {} in place", kept.display()))?;
            }
            if let TaskMeasure::Trace { .. } = plan.spec.measure {
                let kept = folder.trace(index);
                std::fs::rename(folder.trace_under_way(index), &kept)
                    .with_context(|| format!("putting {} in place", kept.display()))?;
            }
            std::fs::rename(folder.report(index), &result)
                .with_context(|| format!("putting {} in place", result.display()))?;
            let _ = std::fs::remove_file(folder.checkpoint(index));
            let _ = std::fs::remove_file(folder.failure(index));
        }
        Ok(finished)
    });
    if let Err(e) = &outcome {
        let _ = write_atomically(&folder.failure(index), format!("{e:#}\n").as_bytes());
    }
    outcome
}

/// Measures the equation of state at `task`'s area fraction and seed into its report.
fn eos_task(folder: &Folder, eos: &EosMeasure, task: &Task) -> anyhow::Result<Finished> {
    let phi = task
        .area_fraction
        .context("an `eos` task has an area fraction")?;
    let options = eos.options(phi, task.seed.unwrap_or(EosOptions::default().seed));
    crate::cli::run::set_threads(Some(1));
    let point = measure(&options, phi).map_err(anyhow::Error::msg)?;
    let path = folder.report(task.index);
    let text = serde_json::to_string_pretty(&point).context("the point as JSON")?;
    write_atomically(&path, text.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(Finished::Completed)
}

/// Runs `task` from its scene, or from the checkpoint an earlier try left.
fn run_task(plan: &Plan, task: &Task) -> anyhow::Result<Finished> {
    let folder = &plan.folder;
    let checkpoint = folder.checkpoint(task.index);
    let Some(task_length) = task.length else {
        bail!("a `report` task has a length");
    };
    let input = match (&task.scene, &plan.spec.scene, &plan.spec.particles) {
        (Some(own), _, _) => Input::Scene(folder.dir.join(own)),
        (None, Some(scene), _) => Input::Scene(scene.clone()),
        (None, None, Some(particles)) => Input::Particles(particles.clone(), plan.spec.boundary),
        (None, None, None) => bail!("a `report` task has a scene or a particle file"),
    };
    let length = match task_length {
        SpecLength::Steps(steps) => Length::Steps(steps),
        SpecLength::Seconds(seconds) => Length::Seconds(seconds),
    };
    let mut options = RunOptions {
        input,
        solver: task
            .solver
            .as_deref()
            .map(|s| s.parse().map(SolverChoice::Fixed))
            .transpose()
            .map_err(|e| anyhow::anyhow!("solver: {e}"))?,
        tolerance: None,
        dt: task.dt,
        length,
        seed: task.seed,
        placement: None,
        area_fraction: task.area_fraction,
        report: Some(folder.report(task.index)),
        dump: plan.spec.dump.then(|| folder.dump(task.index)),
        threads: Some(1),
        vector: true,
        checkpoint: Some(checkpoint.clone()),
        every: None,
    };
    if checkpoint.exists() {
        let saved = Checkpoint::read(&checkpoint)?;
        let total = match task_length {
            SpecLength::Steps(steps) => steps,
            SpecLength::Seconds(seconds) => (seconds / saved.dt()).ceil() as u64,
        };
        let done = saved.steps();
        if done >= total {
            // It ended, and was stopped before its report was put in place: run it again.
            std::fs::remove_file(&checkpoint)
                .with_context(|| format!("removing {}", checkpoint.display()))?;
        } else {
            say(format_args!(
                "task {}: going on from {} at step {done} of {total}",
                task.index,
                checkpoint.display()
            ));
            options = RunOptions {
                input: Input::Resume(checkpoint),
                solver: None,
                dt: None,
                seed: None,
                area_fraction: None,
                length: Length::Steps(total - done),
                ..options
            };
        }
    }
    crate::cli::run::run(options)
}

/// Removes `root` when it holds `sweeps` (folders under it, or `root` itself) and every one is
/// finished: a finished run is run again whole (the code or the machine may have changed); an
/// unfinished one goes on where it stopped.
pub(crate) fn start_over_if_finished(root: &Path, sweeps: &[PathBuf]) -> anyhow::Result<()> {
    if root.exists() && sweeps.iter().all(|dir| finished(dir)) {
        std::fs::remove_dir_all(root)
            .with_context(|| format!("removing the finished run's {}", root.display()))?;
    }
    Ok(())
}

/// Whether `dir` holds a planned sweep whose every task is done.
fn finished(dir: &Path) -> bool {
    Plan::open(dir).is_ok_and(|plan| {
        plan.tasks
            .iter()
            .all(|task| plan.folder.result(task.index).exists())
    })
}

/// The points of the `eos` sweep in `dir`, in task order; every task must be done.
pub(crate) fn eos_points(dir: &Path) -> anyhow::Result<Vec<crate::tools::eos::EosPoint>> {
    let plan = Plan::open(dir)?;
    plan.tasks
        .iter()
        .map(|task| {
            figures::eos_point(&plan.result(task.index)?)
                .with_context(|| format!("{}", plan.folder.result(task.index).display()))
        })
        .collect()
}

/// `sweep status`: how many tasks are done, started (a checkpoint, or running), failed (with
/// the first line of why) and waiting.
pub fn status(dir: &Path) -> anyhow::Result<()> {
    let plan = Plan::open(dir)?;
    let folder = &plan.folder;
    let (mut done, mut started, mut waiting) = (0, 0, 0);
    let mut failed = Vec::new();
    for task in &plan.tasks {
        let i = task.index;
        if folder.result(i).exists() {
            done += 1;
        } else if let Ok(why) = std::fs::read_to_string(folder.failure(i)) {
            failed.push((i, why.lines().next().unwrap_or("").to_owned()));
        } else if folder.checkpoint(i).exists() || folder.report(i).exists() {
            started += 1;
        } else {
            waiting += 1;
        }
    }
    say(format_args!(
        "{} tasks: {done} done, {started} started (running, or stopped with a checkpoint), {} \
         failed, {waiting} waiting",
        plan.tasks.len(),
        failed.len()
    ));
    for (i, why) in &failed {
        say(format_args!("  task {i} failed: {why}"));
    }
    Ok(())
}
