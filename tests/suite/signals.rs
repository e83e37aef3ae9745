//! Signals through the real binary: SIGINT or SIGTERM ends a run after a whole step with its
//! report, final state and checkpoint written; a long event-driven step is cut short within a
//! second of the signal; a signal while a particle file is read or the circles are placed or
//! compressed ends the run at once, writing nothing; and a second signal ends it at once
//! without touching what was there.
#![cfg(unix)]

use crate::common::binary::scratch_dir;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::binary::{command, successful};

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

/// Starts a long run of the 10 000-circle gas writing everything, and waits until it has
/// written its first checkpoint (so it is stepping).
fn start_long_run(dir: &Path) -> Child {
    let p = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let checkpoint = dir.join("c");
    let child = command(&[
        "run",
        "--scene",
        "assets/scenes/gas.ron",
        "--solver",
        "exact",
        "--steps",
        "10000000",
        "--report",
        &p("r.json"),
        "--dump",
        &p("d.txt"),
        "--checkpoint",
        &p("c"),
        "--every",
        "3",
    ])
    .stdout(Stdio::null())
    .stderr(Stdio::null())
    .spawn()
    .unwrap();
    let start = Instant::now();
    while !checkpoint.exists() {
        assert!(start.elapsed() < Duration::from_secs(120), "no checkpoint");
        std::thread::sleep(Duration::from_millis(20));
    }
    child
}

/// The command for `steps` steps of the scene `scene_text` (written into `dir`) with a report
/// over a file that holds "old", and that report's path: a run a signal ends before it steps
/// must leave it so.
fn run_over_old_report(dir: &Path, scene_text: &str, steps: u64) -> (Command, PathBuf) {
    let (scene, report) = (dir.join("scene.ron"), dir.join("r.json"));
    std::fs::write(&scene, scene_text).unwrap();
    std::fs::write(&report, "old").unwrap();
    let run = command(&[
        "run",
        "--scene",
        scene.to_str().unwrap(),
        "--steps",
        &steps.to_string(),
        "--report",
        report.to_str().unwrap(),
    ]);
    (run, report)
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

#[test]
fn a_signal_ends_the_run_after_a_step_with_everything_written() {
    for (name, code) in [("INT", 130), ("TERM", 143)] {
        let dir = scratch_dir("signals", &format!("signal-{name}"));
        let mut child = start_long_run(&dir);
        signal(&child, name);
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "SIG{name}");
        let report: serde_json::Value = serde_json::from_str(&text(&dir.join("r.json"))).unwrap();
        assert_eq!(report["interrupted"], true);
        let steps = report["steps"].as_u64().unwrap();
        assert!(steps >= 3, "{steps} steps");
        // The dump is the state after the last whole step, and the checkpoint goes on from it.
        let dump = text(&dir.join("d.txt"));
        assert_eq!(dump.lines().count(), 10_029);
        let c = dir.join("c");
        let again = dir.join("again.json");
        successful(&[
            "run",
            "--resume",
            c.to_str().unwrap(),
            "--steps",
            "1",
            "--report",
            again.to_str().unwrap(),
        ]);
        let again: serde_json::Value = serde_json::from_str(&text(&again)).unwrap();
        assert_eq!(again["steps"].as_u64(), Some(steps + 1));
        assert_eq!(again["interrupted"], false);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn a_signal_ends_a_long_exact_step_at_once_with_everything_written() {
    let dir = scratch_dir("signals", "long-step");
    let (report, checkpoint) = (dir.join("r.json"), dir.join("c"));
    // Steps of 60 s of the 10 000-circle gas: seconds of events each. The checkpoint after the
    // first says the second has begun.
    let mut child = command(&[
        "run",
        "--scene",
        "assets/scenes/gas.ron",
        "--solver",
        "exact",
        "--dt",
        "60",
        "--steps",
        "3",
        "--report",
        report.to_str().unwrap(),
        "--checkpoint",
        checkpoint.to_str().unwrap(),
        "--every",
        "1",
    ])
    .stdout(Stdio::null())
    .stderr(Stdio::null())
    .spawn()
    .unwrap();
    wait_for(&checkpoint);
    signal(&child, "TERM");
    let sent = Instant::now();
    let status = child.wait().unwrap();
    let took = sent.elapsed();
    assert_eq!(status.code(), Some(143));
    let report: serde_json::Value = serde_json::from_str(&text(&report)).unwrap();
    assert_eq!(report["interrupted"], true);
    // The second step was ended by drifting to its end, as when the event budget runs out.
    assert_eq!(report["steps"].as_u64(), Some(2), "{report}");
    assert_eq!(report["budget_exhausted"].as_u64(), Some(1), "{report}");
    assert!(
        took < Duration::from_secs(2),
        "the run took {took:?} to stop"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Waits until `path` exists (a run's first checkpoint, put in place whole by a rename).
fn wait_for(path: &Path) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "{} never came",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_signal_while_circles_are_placed_ends_the_run_at_once_and_writes_nothing() {
    // Four million circles at random, or a hundred thousand compressed to 0.8: seconds to
    // place in a release build, minutes in a test build.
    let random = "(arena: (size: (560.0, 560.0), boundary: periodic), \
         effects: (collisions: true), spawn: (count: 4000000, radius: (0.05, 0.1), seed: 1))";
    let pack = "(arena: (size: (63.0, 63.0), boundary: walls), effects: (collisions: true), \
         spawn: (placement: pack, count: 100000, radius: (0.1, 0.1), seed: 1))";
    signalled_while_placing(random, "placing at random 4000000");
    signalled_while_placing(pack, "compressing 100000");
    // Fewer circles than that, in a box that holds a few hundred: each of the rest is tried 200
    // times (seconds to minutes). It was placed without a word.
    let crowded = "(spawn: (count: 999999, seed: 1))";
    signalled_while_placing(crowded, "placing at random 999999");
}

/// Runs `scene`, signals it as soon as it says it is `placing` (its first line), and asserts
/// it ends within a second writing nothing.
fn signalled_while_placing(scene_text: &str, placing: &str) {
    let dir = scratch_dir("signals", "placing");
    let (mut run, report) = run_over_old_report(&dir, scene_text, 10);
    let mut child = run
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The run says it is placing them, then places them: the signal comes while it does.
    let mut stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut said = String::new();
    std::io::BufRead::read_line(&mut stderr, &mut said).unwrap();
    assert!(said.contains(placing), "{said}");
    signal(&child, "TERM");
    let sent = Instant::now();
    let status = child.wait().unwrap();
    let took = sent.elapsed();
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut stdout).unwrap();
    assert_eq!(status.code(), Some(143), "{stdout}");
    assert!(
        stdout.contains("while placing or spawning circles"),
        "{stdout}"
    );
    assert_eq!(
        text(&report),
        "old",
        "nothing was run, so nothing is replaced"
    );
    assert!(
        took < Duration::from_secs(1),
        "the run took {took:?} to stop"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_second_signal_ends_the_run_at_once_and_leaves_old_outputs_alone() {
    let dir = scratch_dir("signals", "twice");
    // 200 000 circles under the course's method: after the first signal the run ends its step
    // and writes a report, the final state and a checkpoint of them, a fraction of a second to
    // seconds; the second signal comes while it does, as soon as the run says it heard the first.
    let scene = "(arena: (size: (1000.0, 1000.0)), effects: (collisions: true), \
         spawn: (count: 200000, radius: (0.1, 0.1), seed: 1), solver: \"discrete\")";
    let (mut run, report) = run_over_old_report(&dir, scene, 1_000_000);
    let (dump, checkpoint) = (dir.join("d.txt"), dir.join("c"));
    std::fs::write(&dump, "old").unwrap();
    let mut child = run
        .args(["--dump", dump.to_str().unwrap()])
        .args(["--checkpoint", checkpoint.to_str().unwrap(), "--every", "1"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&checkpoint);
    signal(&child, "INT");
    let stderr = std::io::BufReader::new(child.stderr.take().unwrap());
    // Kept open to the end: a run whose standard error is closed fails on its next line.
    let mut lines = std::io::BufRead::lines(stderr);
    let heard = lines
        .by_ref()
        .map(Result::unwrap)
        .find(|line| line.contains("SIGINT: finishing cleanly"));
    assert!(heard.is_some(), "the run never said it heard the signal");
    signal(&child, "INT");
    let start = Instant::now();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert!(
        start.elapsed() < Duration::from_secs(1),
        "did not end at once"
    );
    assert_eq!(text(&report), "old");
    assert_eq!(text(&dump), "old");
    // The scene, the two old outputs and the checkpoint of a whole step: nothing half-written.
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["c", "d.txt", "r.json", "scene.ron"], "a stray file");
    drop(lines);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_signal_while_a_particle_file_is_read_ends_the_run_and_writes_nothing() {
    // A pipe of blank lines that never ends: the reader skips them one by one, within the
    // size limit for a long while. A signal ends it there (the first signal only asks, so the
    // reader must ask back).
    let dir = scratch_dir("signals", "reading");
    let report = dir.join("r.json");
    std::fs::write(&report, "old").unwrap();
    let mut child = command(&[
        "run",
        "--particles",
        "/dev/stdin",
        "--steps",
        "1",
        "--report",
        report.to_str().unwrap(),
    ])
    .stdin(Stdio::piped())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped())
    .spawn()
    .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let (read_tx, read_rx) = std::sync::mpsc::channel();
    let feeder = std::thread::spawn(move || {
        let blank = vec![b'\n'; 1 << 16];
        let mut written = 0usize;
        while std::io::Write::write_all(&mut stdin, &blank).is_ok() {
            written += blank.len();
            // Past what the pipe holds: the run is reading.
            if written == 1 << 22 {
                read_tx.send(()).unwrap();
            }
        }
    });
    read_rx
        .recv_timeout(Duration::from_secs(60))
        .expect("the run reads its input");
    signal(&child, "TERM");
    let sent = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if sent.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            panic!("the run went on reading after the signal");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    feeder.join().unwrap();
    let mut stdout = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut stdout).unwrap();
    assert_eq!(status.code(), Some(143), "{stdout}");
    assert!(stdout.contains("while reading the input"), "{stdout}");
    assert_eq!(
        text(&report),
        "old",
        "nothing was run, so nothing is replaced"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
