//! `moving_circles run`: load a scene or particle file (or resume a checkpoint), apply the
//! command line's overrides (solver, or `auto` within a tolerance; step; seed; length), step it
//! headless with a progress bar on a terminal, print a summary and write the report, the final
//! state and checkpoints. SIGINT and SIGTERM end it after the current step with all of those
//! written (a long event-driven step ends at once, through [`StopRequest`]), saying on standard
//! error that it heard the signal; a second signal ends it at once.

mod options;
mod setup;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use anyhow::{Context, bail};
use bevy::prelude::App;

use crate::base::circle::snapshot;
use crate::step::schedule::{StepTotals, StopRequest};
use crate::tools::checkpoint::Checkpoint;
use crate::tools::io::{self, say};
use crate::tools::run::{Progress, Report, advance, default_sampling, out_of_range, sample_end};
use crate::tools::scene::particles;
pub use options::{Finished, Input, Length, MAX_STEPS, MAX_THREADS, RunOptions, SolverChoice};
pub(crate) use setup::set_threads;
use setup::{check_outputs, configure, start, steps_of};

/// Runs `options` to the end (or to a signal): loads, steps, prints the summary, writes the
/// outputs.
pub fn run(options: RunOptions) -> anyhow::Result<Finished> {
    check_outputs(&options)?;
    if options.every == Some(0) {
        bail!("--every must be at least 1");
    }
    let interrupts = Interrupts::install()?;
    // Before any App, resumed or new, is made: neither changes a result.
    set_threads(options.threads);
    crate::base::vector::allow(options.vector);
    let (mut app, mut progress, source, dt) = match &options.input {
        Input::Resume(path) => {
            let spawn = options.placement.is_some() || options.area_fraction.is_some();
            if options.solver.is_some() || options.dt.is_some() || options.seed.is_some() || spawn {
                bail!(
                    "--resume goes on with the checkpoint's settings: no --solver, --dt, --seed, \
                     --placement or --area-fraction"
                );
            }
            let checkpoint = Checkpoint::read(path)?;
            let source = checkpoint.source.clone();
            let origin = path.display().to_string();
            let (app, progress) = checkpoint.resume(&origin)?;
            let dt = app
                .world()
                .resource::<bevy::time::Time<bevy::time::Fixed>>();
            let dt = dt.timestep().as_secs_f64();
            (app, progress, source, dt)
        }
        input => {
            let raised = || interrupts.raised().is_some();
            let (config, source) = match configure(input, &options, raised) {
                Ok(loaded) => loaded,
                // A signal while the input was read (a particle file is read line by line, and
                // a pipe may never end): nothing was run, every output is left as it was.
                Err(_) if let Some(signal) = interrupts.raised() => {
                    say(format_args!(
                        "interrupted by signal {signal} while reading the input; nothing written"
                    ));
                    return Ok(Finished::Interrupted { signal });
                }
                Err(e) => return Err(e),
            };
            if config.effects.has_friction() && !config.solver.models_friction() {
                let solver = config.solver;
                say(format_args!(
                    "note: friction acts under `soft` only; `{solver}` treats circles as smooth"
                ));
            }
            if config.effects.is_rough() && !config.solver.models_rough_hits() {
                let solver = config.solver;
                say(format_args!(
                    "note: rough hits (tangential restitution) act under `swept` and `exact` only; \
                     `{solver}` treats circles as smooth"
                ));
            }
            let dt = config.dt;
            let Some(mut app) = start(config, &source, interrupts.stop_request())? else {
                // Nothing was run: every output is left as it was.
                let signal = interrupts.raised().unwrap_or_default();
                say(format_args!(
                    "interrupted by signal {signal} while placing or spawning circles; nothing written"
                ));
                return Ok(Finished::Interrupted { signal });
            };
            let progress = Progress::start(app.world_mut());
            (app, progress, source, dt)
        }
    };
    app.insert_resource(interrupts.stop_request());
    let steps = steps_of(options.length, dt)?;
    let first = app.world().resource::<StepTotals>().steps;
    let until = first.saturating_add(steps);
    let bar = indicatif::ProgressBar::new(steps).with_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  eta {eta}")
            .expect("valid template"),
    );
    let sampling = default_sampling(
        app.world()
            .resource::<crate::game::spawn::SpawnReport>()
            .placed,
    );
    // What could not be written; the other outputs are written all the same.
    let mut failed: Vec<anyhow::Error> = Vec::new();
    // Whether a sample's state has left the range of values. Nothing of such a state may be
    // written, and a run there spends its steps at speeds past what the clock resolves: it
    // stops at that sample, not at its end (one that would have come back within the range by
    // its end, which drag can do, is refused all the same).
    let left_range = std::cell::Cell::new(false);
    let stopped = loop {
        let now = app.world().resource::<StepTotals>().steps;
        // Where the next checkpoint is due, or the end.
        let due = match (&options.checkpoint, options.every) {
            (Some(_), Some(every)) => until.min((now / every + 1).saturating_mul(every)),
            _ => until,
        };
        // The first step alone, to say at once how long a run of slow steps will take.
        let next = if now == first {
            due.min(first + 1)
        } else {
            due
        };
        let stop = || interrupts.raised().is_some() || left_range.get();
        let before = progress.stepping;
        let stopped = advance(&mut app, &mut progress, next, sampling, stop, |s| {
            bar.set_position(s.step - first);
            if out_of_range(s.world).is_some() {
                left_range.set(true);
            }
        });
        if left_range.get() {
            break false;
        }
        if now == first && !stopped {
            say_if_slow(progress.stepping - before, until - first);
        }
        if stopped || next >= until {
            break stopped;
        }
        if next < due {
            continue;
        }
        if let Some(path) = &options.checkpoint
            && let Err(e) = write_checkpoint(&mut app, &source, &progress, path)
        {
            // A periodic checkpoint that cannot be written (a full disk) ends the run here,
            // with the report and the dump of where it got to.
            failed.push(e);
            break true;
        }
    };
    let checkpoint_failed = !failed.is_empty();
    bar.finish_and_clear();

    let mut ended = progress;
    sample_end(&mut app, &mut ended, sampling, |_| {});
    let mut report = Report::new(app.world_mut(), &source, &ended);
    report.interrupted = stopped;
    print_summary(&report);
    if report.final_penetration >= SUNK {
        eprintln!(
            "moving_circles: warning: circles ended {:.2} radii deep in each other \
             (final_penetration): the solver's settings do not hold this scene (under `soft`, \
             a stiffer soft.hertz, more substeps or a shorter dt do)",
            report.final_penetration
        );
    }
    if !report.is_finite() {
        bail!(
            "the run's state became non-finite ({} circles); nothing was written",
            report.non_finite
        );
    }
    if let Some((i, e)) = out_of_range(app.world_mut()) {
        let also: Vec<String> = failed.iter().map(|e| format!("; {e:#}")).collect();
        let step = app.world().resource::<StepTotals>().steps;
        bail!(
            "the run's state left the range of values a file may hold by step {step} (circle \
             {i}'s {e}); the run stopped there and no output of it was written (checkpoints of \
             earlier steps are kept){}",
            also.concat()
        );
    }
    // Every output is written beside its place first, and only then are they put in place, one
    // rename after another: a second signal while they are written (seconds, for millions of
    // circles) leaves the old set, not some old and some new.
    let mut staged = Vec::new();
    let mut stage = |what: &str, path: &std::path::Path, bytes: anyhow::Result<Vec<u8>>| match bytes
        .and_then(|bytes| {
            io::stage(path, &bytes)
                .with_context(|| format!("writing the {what} to {}", path.display()))
        }) {
        Ok(file) => staged.push((what.to_owned(), path.to_owned(), file)),
        Err(e) => failed.push(e),
    };
    if let Some(path) = &options.report {
        let json = serde_json::to_string_pretty(&report).context("serialising the report");
        stage("report", path, json.map(|json| (json + "\n").into_bytes()));
    }
    if let Some(path) = &options.dump {
        let state = snapshot(app.world_mut());
        stage(
            "final state",
            path,
            Ok(particles::format(&state).into_bytes()),
        );
    }
    // Once failed, the checkpoint is not tried again: the run stopped where it failed.
    if let Some(path) = &options.checkpoint
        && !checkpoint_failed
    {
        stage(
            "checkpoint",
            path,
            checkpoint_bytes(&mut app, &source, &progress, path),
        );
    }
    for (what, path, file) in staged {
        if let Err(e) = file.commit() {
            failed.push(
                anyhow::Error::new(e).context(format!("writing the {what} to {}", path.display())),
            );
        }
    }
    if !failed.is_empty() {
        let all: Vec<String> = failed.iter().map(|e| format!("{e:#}")).collect();
        bail!("{} (the other outputs were written)", all.join("; "));
    }
    if stopped {
        // A signal asked to end now and the process exits next: the system takes the world's
        // memory back at once, where freeing millions of circles one by one takes a quarter
        // of a second.
        std::mem::forget(app);
    }
    Ok(match interrupts.raised() {
        Some(signal) if stopped => {
            say(format_args!(
                "interrupted by signal {signal} after step {}; outputs written",
                report.steps
            ));
            Finished::Interrupted { signal }
        }
        // After the last step, while the outputs were written: they are whole, and the exit
        // status still says a signal came.
        Some(signal) => {
            say(format_args!(
                "signal {signal} came after the last step, while the outputs were written; all \
                 were written"
            ));
            Finished::Interrupted { signal }
        }
        None => Finished::Completed,
    })
}

/// SIGINT and SIGTERM, caught: the first asks the run to stop after the current step; a second
/// ends the process at once with 130 / 143, leaving every output as it was (each is replaced
/// whole or not at all, and nothing half-written stays beside it): [`watch_signals`].
struct Interrupts {
    signal: Arc<AtomicUsize>,
    /// Set by the first signal: what a long step polls ([`StopRequest`]).
    once: Arc<AtomicBool>,
}

impl Interrupts {
    fn install() -> anyhow::Result<Self> {
        use signal_hook::consts::{SIGINT, SIGTERM};
        use signal_hook::flag;
        let once = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for number in [SIGINT, SIGTERM] {
            flag::register(number, Arc::clone(&once))
                .and_then(|_| flag::register_usize(number, Arc::clone(&signal), number as usize))
                .context("installing the signal handlers")?;
        }
        watch_signals()?;
        Ok(Self { signal, once })
    }

    /// The request a long step polls, to end the step at once after the first signal.
    fn stop_request(&self) -> StopRequest {
        StopRequest(Arc::clone(&self.once))
    }

    /// The signal that asked the run to stop, if one did.
    fn raised(&self) -> Option<i32> {
        match self.signal.load(Ordering::Relaxed) {
            0 => None,
            n => Some(n as i32),
        }
    }
}

/// Watches SIGINT and SIGTERM from a thread of its own. The first is acknowledged on standard
/// error (a run finishing a long step or writing millions of circles is otherwise silent until
/// it ends, and a user or a script waits for that line before deciding on a second signal);
/// the second ends the process at once with 130 or 143, removing any output half-written
/// beside its place ([`io::exit_removing_staged`]), so old outputs stay whole and alone.
fn watch_signals() -> anyhow::Result<()> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
        .context("installing the signal handlers")?;
    use std::io::Write;
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut signals = signals.forever();
            if let Some(signal) = signals.next() {
                let name = signal_hook::low_level::signal_name(signal).unwrap_or("a signal");
                // Not `eprintln!`, which panics on a closed standard error: this thread must
                // live to hear the second signal.
                let _ = writeln!(
                    std::io::stderr(),
                    "moving_circles: {name}: finishing cleanly; a second signal ends the run at \
                     once, leaving old outputs in place"
                );
            }
            if let Some(signal) = signals.next() {
                io::exit_removing_staged(128 + signal);
            }
        })
        .context("starting the signal thread")?;
    Ok(())
}

/// A first step slower than this is announced with what the whole run will take.
const SLOW_STEP: std::time::Duration = std::time::Duration::from_secs(1);

/// Says, on standard error, what `steps` steps will take if the first took `first`, when that
/// is slow ([`SLOW_STEP`]): a run of 5-second steps otherwise looks like a hang.
fn say_if_slow(first: std::time::Duration, steps: u64) {
    if let Some(notice) = slow_notice(first, steps) {
        eprintln!("moving_circles: {notice}");
    }
}

/// [`say_if_slow`]'s notice, if any.
fn slow_notice(first: std::time::Duration, steps: u64) -> Option<String> {
    if first < SLOW_STEP || steps < 2 {
        return None;
    }
    let whole = first.as_secs_f64() * steps as f64;
    let (amount, unit) = match whole {
        s if s < 120.0 => (s, "s"),
        s if s < 7200.0 => (s / 60.0, "min"),
        s => (s / 3600.0, "h"),
    };
    Some(format!(
        "the first step took {:.1} s; {steps} steps will take about {amount:.0} {unit}",
        first.as_secs_f64()
    ))
}

fn write_checkpoint(
    app: &mut App,
    source: &str,
    progress: &Progress,
    path: &std::path::Path,
) -> anyhow::Result<()> {
    let bytes = checkpoint_bytes(app, source, progress, path)?;
    io::write_atomically(path, &bytes)
        .with_context(|| format!("writing the checkpoint to {}", path.display()))
}

/// The checkpoint of `app` as bytes for `path`, checked as our reader checks it, so that no
/// checkpoint we write is one it refuses (a state past the range of values, a cached contact
/// impulse past its bound).
fn checkpoint_bytes(
    app: &mut App,
    source: &str,
    progress: &Progress,
    path: &std::path::Path,
) -> anyhow::Result<Vec<u8>> {
    let checkpoint = Checkpoint::take(app.world_mut(), source, progress);
    if let Err(why) = checkpoint.check() {
        bail!(
            "not writing the checkpoint to {}: our own reader would refuse it: {why}",
            path.display()
        );
    }
    Ok(checkpoint.to_bytes())
}

/// Overlap at the end (in the smaller radius) from which a run warns that circles sank into
/// each other: no solver's resting contacts come near it unless its settings cannot hold the
/// scene.
const SUNK: f64 = 1.0;

fn print_summary(r: &Report) {
    say(format_args!(
        "{} circles, {}, {} steps of {:.6} s in {:.3} s ({:.4} ms/step)",
        r.n, r.solver, r.steps, r.dt, r.wall_seconds, r.ms_per_step
    ));
    say(format_args!(
        "energy drift {:+.3e}, max penetration {:.3e}, collisions {} pair / {} wall, escaped {}, non-finite {}",
        r.energy_drift,
        r.max_penetration,
        r.pair_collisions,
        r.wall_collisions,
        r.escaped,
        r.non_finite
    ));
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::slow_notice;

    #[test]
    fn a_slow_first_step_is_announced_with_the_whole_run() {
        assert_eq!(slow_notice(Duration::from_millis(999), 1000), None);
        assert_eq!(slow_notice(Duration::from_secs(30), 1), None);
        let notice = |secs, steps| slow_notice(Duration::from_secs(secs), steps).unwrap();
        assert!(notice(2, 10).ends_with("10 steps will take about 20 s"));
        assert!(notice(5, 100).ends_with("about 8 min"));
        assert!(notice(5, 100_000).ends_with("about 139 h"));
    }
}
