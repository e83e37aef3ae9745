//! How a sweep runs on Slurm: the array's settings in a spec, and the batch script `sweep
//! plan` writes for them.

use std::path::Path;

use anyhow::Context;
use serde::{Deserialize, Serialize};

/// How the Slurm array runs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SlurmSettings {
    /// Tasks running at once (`--array=0-N%K`).
    pub concurrency: u32,
    /// Each task's time limit (`--time`, e.g. `"00:30:00"`).
    pub time_limit: String,
    /// Seconds before the limit at which a task is told to checkpoint and stop (SIGTERM); it
    /// is requeued and goes on from its checkpoint.
    pub warn_seconds: u32,
}

impl Default for SlurmSettings {
    fn default() -> Self {
        Self {
            concurrency: 16,
            time_limit: "01:00:00".into(),
            warn_seconds: 60,
        }
    }
}

/// The Slurm batch script of the whole array.
pub(super) fn batch_script(
    slurm: &SlurmSettings,
    tasks: usize,
    dir: &Path,
) -> anyhow::Result<String> {
    let program = std::env::current_exe().context("finding this program")?;
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

/// Whether `s` is a Slurm time limit: `M`, `M:S`, `H:M:S`, `D-H`, `D-H:M` or `D-H:M:S`.
pub(super) fn is_slurm_time(s: &str) -> bool {
    let (days, clock) = match s.split_once('-') {
        Some((d, rest)) => (Some(d), rest),
        None => (None, s),
    };
    let numbers = |t: &str| !t.is_empty() && t.len() <= 4 && t.bytes().all(|b| b.is_ascii_digit());
    let parts: Vec<&str> = clock.split(':').collect();
    days.is_none_or(numbers) && parts.len() <= 3 && parts.iter().all(|p| numbers(p))
}
