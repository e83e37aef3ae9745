//! Hostile and clumsy input, through the real binary: each class of broken promise found by
//! black-box runs stays fixed. A run must end with a clear one-line refusal (or succeed), never
//! a panic or an abort, and nothing from a file may reach the terminal as a raw control byte.
#![cfg(unix)]

use std::os::unix::fs::FileTypeExt;
use std::path::PathBuf;
use std::process::{Command, Output};

fn moving_circles(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_moving_circles"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("DISPLAY", "")
        .args(args)
        .output()
        .expect("runs")
}

/// `run` on two steps of the classic scene, with `extra` flags.
fn run_classic(extra: &[&str]) -> Output {
    let mut args = vec![
        "run",
        "--scene",
        "assets/scenes/classic.ron",
        "--steps",
        "2",
    ];
    args.extend_from_slice(extra);
    moving_circles(&args)
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mc-hostile-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Asserts the run was refused with exit code 1 and one line on stderr that contains every
/// `expected` piece, and that nothing panicked or aborted.
fn assert_refused(out: &Output, expected: &[&str]) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "exit status, stderr:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "one line:\n{stderr}");
    for piece in expected {
        assert!(stderr.contains(piece), "expected `{piece}` in:\n{stderr}");
    }
}

#[test]
fn radii_spanning_the_whole_f64_range_are_refused_not_a_panic() {
    let dir = temp_dir("radii");
    // A subnormal radius beside a normal one: the broad phase's ratio of radii overflowed.
    let file = dir.join("subnormal.txt");
    std::fs::write(
        &file,
        "2\n0.25 0.5 0 0 1e-310 1 9 9 9\n0.75 0.5 0 0 0.1 1 9 9 9\n",
    )
    .unwrap();
    let out = moving_circles(&["run", "--particles", file.to_str().unwrap(), "--steps", "3"]);
    assert_refused(
        &out,
        &["line 2: radius 1e-310 is below 1e-9 of the arena's smaller side (1e-9)"],
    );
    // The same in a scene with equal masses (a radius-derived mass would be refused as 0).
    let scene = dir.join("subnormal.ron");
    std::fs::write(
        &scene,
        "(mass: Equal(1.0), circles: [(position: (0.0, 0.0), radius: 1e-310), \
         (position: (3.0, 0.0), radius: 0.5)])",
    )
    .unwrap();
    for command in ["run", "systems"] {
        let mut args = vec![command, "--scene", scene.to_str().unwrap()];
        if command == "run" {
            args.extend(["--steps", "3"]);
        }
        assert_refused(&moving_circles(&args), &["field `circles[0].radius`"]);
    }
    // Spawn rules get the same rule.
    std::fs::write(&scene, "(spawn: (count: 10, radius: (1e-300, 0.5)))").unwrap();
    let out = moving_circles(&["systems", "--scene", scene.to_str().unwrap()]);
    assert_refused(
        &out,
        &[
            "field `spawn.radius`: must be at least 1e-9 of the arena's smaller side (9.0",
            "got (1e-300, 0.5)",
        ],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn thread_counts_past_the_limit_are_an_argument_error_not_an_abort() {
    let out = run_classic(&["--threads", "60000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "clap's usage error:\n{stderr}");
    assert!(
        stderr.contains("--threads") && stderr.contains("1..=1024"),
        "{stderr}"
    );
    let ok = run_classic(&["--threads", "1024"]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
}

#[test]
fn circle_counts_past_the_limit_are_refused_before_anything_is_allocated() {
    // The app checks its overrides before it looks for a display.
    for count in ["18446744073709551615", "20000001"] {
        let out = moving_circles(&["--count", count]);
        assert_refused(
            &out,
            &[&format!(
                "spawn.count: asks for {count} circles; at most 20000000"
            )],
        );
    }
    let out = moving_circles(&[
        "run",
        "--scene",
        "assets/scenes/classic.ron",
        "--steps",
        "1",
        "--dt",
        "60",
    ]);
    assert!(out.status.success(), "the largest dt is accepted");
}

/// Whether `bytes` holds a control byte anywhere but a final newline.
fn has_raw_control(bytes: &[u8]) -> bool {
    let text = String::from_utf8_lossy(bytes);
    text.trim_end_matches('\n').chars().any(char::is_control)
}

#[test]
fn bytes_from_files_and_names_reach_the_terminal_escaped() {
    let dir = temp_dir("escape");
    // An escape sequence that would retitle the terminal, in a number of a particle file.
    let file = dir.join("title.txt");
    std::fs::write(&file, "1\n0.5 \x1b]0;pwned\x07 0 0 0.1 1 9 9 9\n").unwrap();
    let out = moving_circles(&["run", "--particles", file.to_str().unwrap(), "--steps", "1"]);
    assert_refused(&out, &["ry is not a number: `\\u{1b}]0;pwned\\u{7}`"]);
    assert!(!has_raw_control(&out.stderr), "{:?}", out.stderr);

    // Control bytes in a file name: ESC, CR and a newline that would forge a second line.
    let name = dir.join("a\x1b[2J\rb\nmoving_circles: all fine.txt");
    let out = moving_circles(&["run", "--particles", name.to_str().unwrap(), "--steps", "1"]);
    assert_refused(
        &out,
        &["\\u{1b}[2J\\rb\\nmoving_circles: all fine.txt: cannot read"],
    );
    assert!(!has_raw_control(&out.stderr), "{:?}", out.stderr);

    // And in a scene's unknown field, which the RON error quotes.
    let scene = dir.join("field.ron");
    std::fs::write(&scene, "(efects\x07: ())").unwrap();
    let out = moving_circles(&["systems", "--scene", scene.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert!(!has_raw_control(&out.stderr), "{:?}", out.stderr);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn outputs_go_to_regular_files_only_and_never_to_one_file_twice() {
    let dir = temp_dir("outputs");
    let run_to = |flag: &str, path: &std::path::Path| run_classic(&[flag, path.to_str().unwrap()]);
    // A pipe stands in for a device node: replacing it is what must not happen.
    let pipe = dir.join("pipe");
    let made = Command::new("mkfifo").arg(&pipe).status().unwrap();
    assert!(made.success());
    assert_refused(&run_to("--report", &pipe), &["--report: ", "is a pipe"]);
    assert!(
        std::fs::symlink_metadata(&pipe)
            .unwrap()
            .file_type()
            .is_fifo()
    );
    // A directory, and a link that would write somewhere else.
    assert_refused(&run_to("--dump", &dir), &["--dump: ", "is a directory"]);
    let target = dir.join("target.txt");
    std::fs::write(&target, "keep me").unwrap();
    let link = dir.join("link.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    assert_refused(&run_to("--report", &link), &["is a symbolic link"]);
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep me");
    // A folder that does not exist fails before the run, not after it.
    assert_refused(
        &run_to("--report", &dir.join("missing/r.json")),
        &["no such folder"],
    );
    // The report and the dump on one file, however it is spelled.
    let same = dir.join("out.txt");
    let spelled_otherwise = dir.join(".").join("out.txt");
    let out = run_classic(&[
        "--report",
        same.to_str().unwrap(),
        "--dump",
        spelled_otherwise.to_str().unwrap(),
    ]);
    assert_refused(&out, &["--report and --dump name the same file"]);
    assert!(!same.exists(), "nothing written");
    // A good run leaves its outputs and no temporary file.
    let report = dir.join("r.json");
    assert!(run_to("--report", &report).status.success());
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".partial"))
        .collect();
    assert!(report.exists() && left.is_empty(), "{left:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
