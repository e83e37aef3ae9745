//! `sweep run`: a sweep's tasks on this machine, each a `sweep task` process, `--jobs` at a
//! time, each waited for on a thread of its own so that the next starts the moment one ends.

use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};

use super::{Folder, Plan, merge};
use crate::tools::io::say;

/// `sweep run`: every task without a result, `jobs` at a time, each a `sweep task` process
/// writing into `logs/`; then, every task done, [`merge`].
pub fn run(dir: &Path, jobs: usize) -> anyhow::Result<()> {
    if !(1..=MAX_JOBS).contains(&jobs) {
        bail!("--jobs must be from 1 to {MAX_JOBS}, got {jobs}");
    }
    let plan = Plan::open(dir)?;
    let folder = &plan.folder;
    let pending: Vec<usize> = (0..plan.tasks.len())
        .filter(|&i| !folder.result(i).exists())
        .collect();
    let jobs = jobs.min(pending.len().max(1));
    let program = std::env::current_exe().context("finding this program")?;
    let bar = indicatif::ProgressBar::new(pending.len() as u64).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} tasks  eta {eta}  {msg}")
            .expect("valid template"),
    );
    let mut queue = pending.iter().copied();
    // Each task is waited for on a thread of its own, which says when it ends: the next one
    // starts at once, with no polling.
    type Ended = (usize, std::io::Result<ExitStatus>, Duration);
    let (ended, ends) = std::sync::mpsc::channel::<Ended>();
    let started = Instant::now();
    let mut own_time = Duration::ZERO;
    let mut running = 0;
    let mut failed = Vec::new();
    // A task that cannot be started or waited for ends the run, once those running have ended.
    let mut trouble: Option<anyhow::Error> = None;
    loop {
        while trouble.is_none()
            && running < jobs
            && let Some(index) = queue.next()
        {
            match start_task(&program, folder, index) {
                Ok(mut child) => {
                    let ended = ended.clone();
                    let start = Instant::now();
                    std::thread::spawn(move || {
                        let status = child.wait();
                        ended.send((index, status, start.elapsed()))
                    });
                    running += 1;
                }
                Err(e) => trouble = Some(e),
            }
        }
        if running == 0 {
            break;
        }
        let (index, status, took) = ends.recv().expect("a waiting thread per running task");
        running -= 1;
        own_time += took;
        match status {
            Ok(status) if status.success() => {}
            Ok(_) => failed.push(index),
            Err(e) => {
                failed.push(index);
                trouble.get_or_insert(anyhow::anyhow!("waiting for task {index}: {e}"));
            }
        }
        if !failed.is_empty() {
            bar.set_message(format!("{} failed", failed.len()));
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if let Some(e) = trouble {
        return Err(e);
    }
    let done = pending.len() - failed.len();
    say(format_args!(
        "{done} of {} tasks done here ({} done before)",
        pending.len(),
        plan.tasks.len() - pending.len()
    ));
    if !own_time.is_zero() {
        let wall = started.elapsed().as_secs_f64();
        let per_job = own_time.as_secs_f64() / jobs as f64;
        say(format_args!(
            "  in {wall:.1} s; the tasks took {per_job:.1} s a job, from start to end: {:+.1} % \
             in between",
            100.0 * (wall / per_job - 1.0)
        ));
    }
    if !failed.is_empty() {
        failed.sort_unstable();
        // The first failure's own words, so that one failing task says why at once.
        let why = std::fs::read_to_string(folder.failure(failed[0])).unwrap_or_default();
        bail!(
            "tasks {failed:?} failed (task {}: {}): `moving_circles sweep status {}` says why \
             for each",
            failed[0],
            why.lines().next().unwrap_or("see its log"),
            dir.display()
        );
    }
    // Every task has its result: the merge (and its figure) is the sweep's outcome.
    merge(dir)
}

/// Most tasks `sweep run` runs at once (a process and a waiting thread each).
const MAX_JOBS: usize = 1024;

/// Starts `sweep task` for task `index`, its output into its log.
fn start_task(program: &Path, folder: &Folder, index: usize) -> anyhow::Result<Child> {
    let path = folder.log(index);
    let log = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("opening {}", path.display()))?;
    Command::new(program)
        .args(["sweep", "task"])
        .arg(&folder.dir)
        .args(["--index", &index.to_string()])
        .stdin(Stdio::null())
        .stdout(log.try_clone()?)
        .stderr(log)
        .spawn()
        .with_context(|| format!("starting task {index}"))
}
