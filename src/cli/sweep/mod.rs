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
mod local;
mod merge;
pub mod spec;

pub use local::run;
pub use merge::merge;

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::cli::run::{Finished, Input, Length, RunOptions, SolverChoice};
use crate::tools::checkpoint::Checkpoint;
use crate::tools::io::{read_limited, say, write_atomically};
use crate::tools::scene::Scene;
use spec::{MAX_SPEC_BYTES, SpecLength, SweepSpec, Task};

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
}

/// `sweep plan`: checks the spec and its scene, and writes the plan into `out`.
pub fn plan(spec_path: &Path, out: &Path) -> anyhow::Result<()> {
    let mut spec = SweepSpec::read(spec_path).map_err(anyhow::Error::msg)?;
    let base = spec_path.parent().unwrap_or(Path::new("."));
    let scene = base.join(&spec.scene);
    let scene = scene
        .canonicalize()
        .with_context(|| format!("{}: scene: {}", spec_path.display(), scene.display()))?;
    // The scene is checked now, not in each of a thousand tasks; read once, it is also the
    // base of the scenes `field` axes set.
    let base = Scene::read(&scene)?;
    base.to_config(&scene.display().to_string())?;
    spec.scene = scene;
    let text = ron::ser::to_string_pretty(&spec, ron::ser::PrettyConfig::default())
        .context("writing the spec")?;
    let folder = Folder {
        dir: out.to_owned(),
    };
    if let Ok(file) = std::fs::File::open(folder.spec()) {
        let planned = read_limited(file, MAX_SPEC_BYTES).map_err(anyhow::Error::msg)?;
        if planned == text {
            say(format_args!(
                "{} holds this sweep's plan already",
                out.display()
            ));
            return Ok(());
        }
        bail!(
            "{} holds another sweep's plan (its spec.ron differs from {}): plan into an empty \
             folder, or remove that one",
            out.display(),
            spec_path.display()
        );
    }
    for sub in ["results", "failed", "work", "logs", "scenes"] {
        let path = out.join(sub);
        std::fs::create_dir_all(&path).with_context(|| format!("creating {}", path.display()))?;
    }
    let mut tasks = spec.tasks();
    if tasks.iter().any(|t| !t.fields.is_empty()) {
        fields::write_scenes(&base, &mut tasks, out)
            .with_context(|| format!("{}", spec_path.display()))?;
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
    let script = batch_script(&spec, tasks.len(), &dir)?;
    write_atomically(&folder.script(), script.as_bytes())
        .with_context(|| format!("writing {}", folder.script().display()))?;
    // Last: a folder with a spec holds a whole plan.
    write_atomically(&folder.spec(), text.as_bytes())
        .with_context(|| format!("writing {}", folder.spec().display()))?;
    say(format_args!(
        "planned {} tasks in {}",
        tasks.len(),
        out.display()
    ));
    say(format_args!(
        "  here:     moving_circles sweep run {} --jobs 2",
        out.display()
    ));
    say(format_args!(
        "  on Slurm: sbatch {}",
        folder.script().display()
    ));
    Ok(())
}

/// The Slurm batch script of the whole array.
fn batch_script(spec: &SweepSpec, tasks: usize, dir: &Path) -> anyhow::Result<String> {
    let program = std::env::current_exe().context("finding this program")?;
    let slurm = &spec.slurm;
    let quote = |p: &Path| format!("'{}'", p.display().to_string().replace('\'', r"'\''"));
    Ok(format!(
        "#!/bin/bash\n\
         # One Slurm array task per sweep task; each runs `moving_circles sweep task`, which\n\
         # reads its index from SLURM_ARRAY_TASK_ID.\n\
         #SBATCH --job-name=moving_circles-sweep\n\
         # Tasks 0 to {last}, at most {concurrency} at once.\n\
         #SBATCH --array=0-{last}%{concurrency}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --time={time}\n\
         # SIGTERM {warn} s before the time limit: the task writes a checkpoint and stops;\n\
         # requeued, it goes on from the checkpoint.\n\
         #SBATCH --signal=B:TERM@{warn}\n\
         #SBATCH --requeue\n\
         #SBATCH --open-mode=append\n\
         #SBATCH --output={dir}/logs/slurm-%A_%a.log\n\
         # exec: the signal reaches the task itself, not a shell waiting for it.\n\
         exec {program} sweep task {qdir}\n",
        last = tasks - 1,
        concurrency = slurm.concurrency,
        time = slurm.time_limit,
        warn = slurm.warn_seconds,
        dir = dir.display(),
        program = quote(&program),
        qdir = quote(dir),
    ))
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
    let outcome = run_task(&plan, task).and_then(|finished| {
        if finished == Finished::Completed {
            // The dump first: a task with its report in `results/` has everything there.
            if plan.spec.dump {
                let kept = folder.kept_dump(index);
                std::fs::rename(folder.dump(index), &kept)
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

/// Runs `task` from its scene, or from the checkpoint an earlier try left.
fn run_task(plan: &Plan, task: &Task) -> anyhow::Result<Finished> {
    let folder = &plan.folder;
    let checkpoint = folder.checkpoint(task.index);
    let length = match task.length {
        SpecLength::Steps(steps) => Length::Steps(steps),
        SpecLength::Seconds(seconds) => Length::Seconds(seconds),
    };
    let mut options = RunOptions {
        input: Input::Scene(match &task.scene {
            Some(own) => folder.dir.join(own),
            None => plan.spec.scene.clone(),
        }),
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
        let total = match task.length {
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
