//! Hostile and clumsy input, through the real binary: each class of broken promise found by
//! black-box runs stays fixed. A run must end with a clear one-line refusal (or succeed), never
//! a panic or an abort, and nothing from a file may reach the terminal as a raw control byte.
#![cfg(unix)]

use crate::common::binary::scratch_dir;
use std::os::unix::fs::FileTypeExt;
use std::process::{Command, Output};

use crate::common::binary::{assert_refused, moving_circles, under_one_gib};
use moving_circles::base::config::MAX_CIRCLES;

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

#[test]
fn radii_spanning_the_whole_f64_range_are_refused_not_a_panic() {
    let dir = scratch_dir("hostile", "radii");
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
    let just_over = (MAX_CIRCLES + 1).to_string();
    for count in ["18446744073709551615", just_over.as_str()] {
        let out = moving_circles(&["--count", count]);
        assert_refused(
            &out,
            &[&format!(
                "spawn.count: asks for {count} circles; at most {MAX_CIRCLES}"
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
    let dir = scratch_dir("hostile", "escape");
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
    let dir = scratch_dir("hostile", "outputs");
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

#[test]
fn inputs_that_never_end_or_pile_up_are_refused_within_bounded_memory() {
    let dir = scratch_dir("hostile", "bounded");
    // 20 000 circles at one point: 2·10⁸ overlapping pairs if an overlap check lists them.
    let piled = dir.join("piled.txt");
    let mut text = String::from("20000\n");
    for _ in 0..20_000 {
        text.push_str("0.5 0.5 0 0 0.001 1 0 0 0\n");
    }
    std::fs::write(&piled, &text).unwrap();
    let piled = piled.to_str().unwrap();
    let out = under_one_gib(&["run", "--particles", piled, "--steps", "1"]);
    assert_refused(&out, &["line 3: circle overlaps the one on line 2"]);
    // The same pile as a scene asking for the circles to be pushed apart.
    let scene = dir.join("piled.ron");
    let circles = "(position: (0.0, 0.0), radius: 0.01),".repeat(20_000);
    std::fs::write(
        &scene,
        format!("(separate_overlaps: true, circles: [{circles}])"),
    )
    .unwrap();
    let out = under_one_gib(&["run", "--scene", scene.to_str().unwrap(), "--steps", "1"]);
    assert_refused(&out, &["field `separate_overlaps`", "piled on one another"]);
    // Endless devices: one endless line, endless text.
    for (flag, expected) in [
        ("--particles", "/dev/zero: line 1: longer than 4096 bytes"),
        ("--scene", "/dev/zero: larger than the 64 MiB"),
    ] {
        let out = under_one_gib(&["run", flag, "/dev/zero", "--steps", "1"]);
        assert_refused(&out, &[expected]);
    }
    let out = under_one_gib(&["run", "--particles", "/dev/urandom", "--steps", "1"]);
    assert_refused(&out, &["/dev/urandom: line 1:"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn work_that_would_take_hours_is_refused_up_front() {
    // (`--steps` past its range is a usage error: `tests/suite/hostile_two.rs`.)
    let out = moving_circles(&[
        "run",
        "--scene",
        "assets/scenes/classic.ron",
        "--dt",
        "1e-9",
        "--seconds",
        "1000",
    ]);
    assert_refused(
        &out,
        &["--seconds must be positive and at most 10000000000 steps"],
    );
    let dir = scratch_dir("hostile", "hours");
    let scene = dir.join("tries.ron");
    std::fs::write(
        &scene,
        "(spawn: (count: 2, attempts_per_circle: 4294967295))",
    )
    .unwrap();
    let out = moving_circles(&["run", "--scene", scene.to_str().unwrap(), "--steps", "1"]);
    assert_refused(
        &out,
        &["field `spawn.attempts_per_circle`: must be from 1 to 10000"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn one_physical_range_for_every_value_of_every_input() {
    let dir = scratch_dir("hostile", "range");
    // Scenes: each value past the range names its field.
    let scenes = [
        (
            "(arena: (size: (1e200, 1e200)))",
            "field `arena.size`: must be finite and at most 1e30",
        ),
        ("(arena: (center: (1e308, 0.0)))", "field `arena.center`"),
        ("(mass: Area(density: 1e308))", "field `mass`"),
        (
            "(mass: Equal(1e-308))",
            "field `mass`: must be between 1e-30 and 1e30",
        ),
        (
            "(effects: (gravity: (0.0, -1e200)))",
            "field `effects.gravity`",
        ),
        ("(spawn: (speed: (1e155, 1e155)))", "field `spawn.speed`"),
        ("(effects: (drag: 1e300))", "field `effects.drag`"),
        (
            "(circles: [(position: (0.0, 0.0), radius: 0.1, mass: inf)])",
            "field `circles[0].mass`: must be between",
        ),
        (
            "(circles: [(position: (0.0, 0.0), velocity: (1e155, 0.0), radius: 0.1)])",
            "field `circles[0].velocity`",
        ),
        // Gravity within the range but too strong for the step and the circles.
        (
            "(effects: (gravity: (0.0, -1e30)), circles: [(position: (0.0, 0.0), radius: 0.1)])",
            "field `effects.gravity`: |g| = 1e30 is too strong",
        ),
    ];
    for (k, (text, expected)) in scenes.iter().enumerate() {
        let path = dir.join(format!("s{k}.ron"));
        std::fs::write(&path, text).unwrap();
        let out = moving_circles(&["run", "--scene", path.to_str().unwrap(), "--steps", "1"]);
        assert_refused(&out, &[expected]);
    }
    // Particle files: the same rule, the same words.
    for (line, expected) in [
        (
            "0.5 0.5 0 0 0.1 1e308 0 0 0",
            "line 2: mass must be between 1e-30 and 1e30",
        ),
        (
            "0.5 0.5 0 0 0.1 5e-324 0 0 0",
            "line 2: mass must be between",
        ),
        (
            "0.5 0.5 1e155 0 0.1 1 0 0 0",
            "line 2: velocity must be finite and at most 1e30",
        ),
    ] {
        let path = dir.join("p.txt");
        std::fs::write(&path, format!("1\n{line}\n")).unwrap();
        let out = moving_circles(&["run", "--particles", path.to_str().unwrap(), "--steps", "1"]);
        assert_refused(&out, &[expected]);
    }
    // At the edges of the range a run is accepted and everything it writes is finite.
    let path = dir.join("edge.ron");
    std::fs::write(
        &path,
        "(arena: (size: (1e-3, 1e-3)), mass: Equal(1e30), \
          effects: (gravity: (0.0, -3.6e4), restitution: 0.5, wall_restitution: 0.5), \
          spawn: (count: 20, radius: (1e-5, 2e-5), speed: (1e30, 1e30)))",
    )
    .unwrap();
    let (report, dump) = (dir.join("r.json"), dir.join("d.txt"));
    let out = moving_circles(&[
        "run",
        "--scene",
        path.to_str().unwrap(),
        "--steps",
        "50",
        "--report",
        report.to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    // JSON has no NaN or infinity: a non-finite number would have been written as null. Only
    // the pressures may be null, meaning undefined (here: every circle has come to rest).
    for (field, value) in report.as_object().unwrap() {
        assert!(
            !value.is_null() || ["z", "z_wall"].contains(&field.as_str()),
            "{field} is null: {report}"
        );
    }
    let wall_hits = report["wall_collisions"].as_u64().unwrap();
    assert!(
        wall_hits > u64::from(u32::MAX),
        "{wall_hits} wall hits counted past 2³²"
    );
    let dump = std::fs::read_to_string(&dump).unwrap();
    assert!(!dump.contains("inf") && !dump.contains("NaN"), "{dump}");
    std::fs::remove_dir_all(&dir).unwrap();
}
