//! The headless command line as other tools use it: `run` writes every report field, dumps the
//! final state in the particle format, shows no progress bar when piped; `systems` lists what a
//! scene schedules.

use crate::common::binary::{self, scratch_dir, stdout, successful};
use std::path::Path;
use std::process::Command;

/// Runs `moving_circles` with `args` and `--report DIR/r.json`; the report, stdout and stderr.
fn run_with_report(dir: &Path, args: &[&str]) -> (serde_json::Value, String, String) {
    let report = dir.join("r.json");
    let mut args = args.to_vec();
    args.extend(["--report", report.to_str().unwrap()]);
    let out = successful(&args);
    let (stdout, stderr) = (stdout(&out), binary::stderr(&out));
    let json = serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    (json, stdout, stderr)
}

const REPORT_FIELDS: [&str; 17] = [
    "n",
    "solver",
    "dt",
    "steps",
    "sim_seconds",
    "wall_seconds",
    "energy_initial",
    "energy_final",
    "energy_drift",
    "momentum_initial",
    "momentum_final",
    "max_penetration",
    "escaped",
    "non_finite",
    "pair_collisions",
    "wall_collisions",
    "z",
];

#[test]
fn run_writes_every_report_field_and_dumps_the_final_state() {
    let dir = scratch_dir("cli", "run");
    let dump = dir.join("final.txt");
    let (json, stdout, stderr) = run_with_report(
        &dir,
        &[
            "run",
            "--particles",
            "tests/data/particles/billiards5.txt",
            "--seconds",
            "20",
            "--dump",
            dump.to_str().unwrap(),
        ],
    );
    assert!(stdout.contains("16 circles"), "{stdout}");
    assert!(
        stderr.is_empty(),
        "no progress bar when piped, got: {stderr:?}"
    );
    for field in REPORT_FIELDS {
        assert!(json.get(field).is_some(), "report lacks `{field}`: {json}");
    }
    assert_eq!(json["n"], 16);
    assert_eq!(json["steps"], 1200);
    assert_eq!(json["solver"], "discrete");
    assert!(json["wall_seconds"].as_f64().unwrap() > 0.0);
    assert!(
        json["pair_collisions"].as_u64().unwrap() > 0,
        "the cue ball hits the rack"
    );
    // Elastic hits and walls: the energy to rounding (measured: 3.5e-16).
    assert!(
        json["energy_drift"].as_f64().unwrap().abs() < 1e-12,
        "{json}"
    );

    let final_state = moving_circles::tools::scene::particles::read(
        &dump,
        moving_circles::prelude::Boundary::Walls,
    )
    .expect("the dump is a valid particle file");
    assert_eq!(final_state.len(), 16);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn energy_drift_is_finite_when_nothing_moves() {
    let dir = scratch_dir("cli", "rest");
    let input = dir.join("rest.txt");
    std::fs::write(
        &input,
        "2\n0.25 0.5 0 0 0.1 1 9 9 9\n0.75 0.5 0 0 0.1 1 9 9 9\n",
    )
    .unwrap();
    let (json, ..) = run_with_report(
        &dir,
        &[
            "run",
            "--particles",
            input.to_str().unwrap(),
            "--steps",
            "10",
        ],
    );
    assert_eq!(json["energy_drift"], 0.0);
    assert!(
        json["z"].is_null(),
        "pressure is undefined without motion: {json}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn periodic_particle_runs_wrap_instead_of_bouncing() {
    let dir = scratch_dir("cli", "periodic");
    let (json, ..) = run_with_report(
        &dir,
        &[
            "run",
            "--particles",
            "tests/data/particles/diagonal.txt",
            "--boundary",
            "periodic",
            "--seconds",
            "200",
        ],
    );
    assert_eq!(json["boundary"], "periodic");
    assert_eq!(json["wall_collisions"], 0);
    assert_eq!(json["escaped"], 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn systems_lists_what_each_scene_schedules() {
    let listing = |scene: &str| {
        stdout(&successful(&[
            "systems",
            "--scene",
            &Path::new("assets/scenes").join(scene).to_string_lossy(),
        ]))
    };
    let drift = listing("drift.ron");
    let gas = listing("gas.ron");
    assert!(
        drift.lines().any(|l| l == "CircleStep integrate_positions"),
        "{drift}"
    );
    assert!(
        drift.lines().any(|l| l == "CircleStep bounce_off_walls"),
        "{drift}"
    );
    assert!(
        !drift.contains("collide_circles") && !drift.contains("wrap_around"),
        "{drift}"
    );
    assert!(
        gas.lines().any(|l| l == "CircleStep collide_circles"),
        "{gas}"
    );
    assert!(gas.lines().any(|l| l == "CircleStep wrap_around"), "{gas}");
    assert!(!gas.contains("bounce_off_walls"), "{gas}");
}

#[test]
fn a_closed_stdout_is_not_a_crash() {
    // `moving_circles run … | head -1`: the reader goes away before the summary is printed.
    let dir = scratch_dir("cli", "pipe");
    let report = dir.join("r.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_moving_circles"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "--scene",
            "assets/scenes/classic.ron",
            "--steps",
            "200",
            "--report",
            report.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(report.exists(), "the report is still written");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Checks that the final states of `run ARGS --dump` with vector instructions allowed on two
/// threads, and not allowed on one and on two, are the same bytes, `lines` lines (dumped in a
/// scratch folder named `name`).
fn assert_same_state_with_and_without_vector_instructions(name: &str, args: &[&str], lines: usize) {
    // Without AVX2 both runs take the same scalar path and the comparison says nothing: on
    // x86-64 (every machine this suite runs on) the processor must have it.
    #[cfg(target_arch = "x86_64")]
    assert!(
        std::arch::is_x86_feature_detected!("avx2"),
        "this processor has no AVX2: the vector path cannot be compared with the scalar one here"
    );
    let dir = scratch_dir("cli", name);
    let mut dumps = Vec::new();
    for (vector, threads) in [("on", "2"), ("off", "1"), ("off", "2")] {
        let dump = dir.join(format!("vector-{vector}-{threads}.txt"));
        let dump_arg = dump.to_str().unwrap();
        let switches = ["--vector", vector, "--threads", threads, "--dump", dump_arg];
        successful(&[args, &switches[..]].concat());
        dumps.push(std::fs::read_to_string(&dump).unwrap());
    }
    std::fs::remove_dir_all(dir).ok();
    assert_eq!(
        dumps[0].lines().count(),
        lines,
        "a count line and the circles"
    );
    for (k, dump) in dumps.iter().enumerate().skip(1) {
        assert!(
            *dump == dumps[0],
            "{name}: run {k} differs from the vector run"
        );
    }
}

#[test]
fn the_contact_solver_gives_the_same_state_with_and_without_vector_instructions() {
    // The pyramid's 210 stacked circles under `soft`, frictionless: its pairs go through the
    // colour passes, four at a time, in AVX2 where the processor has it unless told not to.
    let args = [
        "run",
        "--scene",
        "assets/scenes/pyramid.ron",
        "--steps",
        "120",
    ];
    assert_same_state_with_and_without_vector_instructions("vector-soft", &args, 211);
}

#[test]
fn the_event_engine_gives_the_same_state_with_and_without_vector_instructions() {
    // The liquid's 4096 circles at area fraction 0.7 in a periodic box under `exact`: each
    // prediction after a collision works out its pair times four at a time in AVX2 where the
    // processor has it unless told not to, pairs across the box's seams among them.
    let args = [
        "run",
        "--scene",
        "assets/scenes/liquid.ron",
        "--steps",
        "40",
    ];
    assert_same_state_with_and_without_vector_instructions("vector-exact", &args, 4097);
}

#[test]
fn the_final_state_does_not_depend_on_the_number_of_threads() {
    // 10k circles: above the size from which the broad phase and the contact pass go parallel
    // (`PARALLEL_FROM`, 4 000), under the course's method and the contact solver.
    let dir = scratch_dir("cli", "threads");
    for solver in ["discrete", "soft"] {
        let mut dumps = Vec::new();
        for threads in ["1", "2", "5"] {
            let dump = dir.join(format!("threads-{solver}-{threads}.txt"));
            successful(&[
                "run",
                "--scene",
                "assets/scenes/gas.ron",
                "--solver",
                solver,
                "--steps",
                "30",
                "--threads",
                threads,
                "--dump",
                dump.to_str().unwrap(),
            ]);
            dumps.push(std::fs::read_to_string(&dump).unwrap());
        }
        assert!(dumps[0].lines().count() > 2 * 4_000);
        assert!(
            dumps.iter().all(|d| *d == dumps[0]),
            "{solver}: states differ by thread count"
        );
    }
    std::fs::remove_dir_all(dir).ok();
}
