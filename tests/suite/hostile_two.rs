//! Hostile and clumsy input, second campaign, through the real binary: arenas of extreme
//! shape run in bounded memory, flags out of range are usage errors (exit 2), and every
//! refusal names what it refuses.
#![cfg(unix)]

use crate::common::binary::scratch_dir;

use crate::common::binary::{assert_refused, stderr, under_one_gib};

#[test]
fn a_long_thin_arena_runs_in_bounded_memory() {
    let dir = scratch_dir("hostile2", "thin");
    // One side 10^18, the other 9: the placement grid once asked for a row of 1.9·10^9 cells.
    // Every solver builds its own grids over the arena, and `systems` places the circles too.
    for boundary in ["walls", "periodic"] {
        for size in ["(1e18, 9.0)", "(9.0, 1e18)"] {
            let scene = dir.join("thin.ron");
            std::fs::write(
                &scene,
                format!(
                    "(arena: (size: {size}, boundary: {boundary}), \
                      spawn: (count: 32, radius: (0.1, 0.2)))"
                ),
            )
            .unwrap();
            let scene = scene.to_str().unwrap();
            for solver in ["discrete", "substeps=4", "soft", "swept", "exact"] {
                let args = ["run", "--scene", scene, "--solver", solver, "--steps", "2"];
                let out = under_one_gib(&args);
                assert!(
                    out.status.success(),
                    "{boundary} {size} {solver}: {}",
                    stderr(&out)
                );
            }
            let out = under_one_gib(&["systems", "--scene", scene]);
            assert!(
                out.status.success(),
                "{boundary} {size} systems: {}",
                stderr(&out)
            );
        }
    }
    // The study on thin arenas: every scene it reads is one, walled.
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    for name in ["gas1k", "gas", "billiards", "fast", "rough_gas", "pyramid"] {
        std::fs::write(
            scenes.join(format!("{name}.ron")),
            "(arena: (size: (1e18, 9.0), boundary: walls), \
              spawn: (count: 32, radius: (0.1, 0.2)))",
        )
        .unwrap();
    }
    let (scenes, out) = (scenes.to_str().unwrap(), dir.join("out"));
    let args = ["accuracy", "--quick", "--scenes", scenes, "--out"];
    let out = under_one_gib(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert!(out.status.success(), "accuracy: {}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn counts_of_zero_are_usage_errors() {
    let scene = "assets/scenes/classic.ron";
    for args in [
        &["run", "--scene", scene, "--steps", "0"][..],
        &["run", "--scene", scene, "--steps", "10000000001"][..],
        &[
            "run",
            "--scene",
            scene,
            "--steps",
            "1",
            "--checkpoint",
            "/tmp/never-written.ckpt",
            "--every",
            "0",
        ][..],
    ] {
        let out = under_one_gib(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        let flag = if args.contains(&"--every") {
            "--every"
        } else {
            "--steps"
        };
        assert!(err.contains(flag), "{args:?}: {err}");
    }
}

#[test]
fn a_refused_compression_names_its_scene() {
    let dir = scratch_dir("hostile2", "pack");
    let scene = dir.join("pack.ron");
    std::fs::write(
        &scene,
        "(arena: (size: (1.0, 1.0)), solver: \"exact\", \
          spawn: (placement: pack, area_fraction: 0.5, radius: (0.02, 0.02)), \
          circles: [(position: (0.0, 0.0), radius: 0.1)])",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let out = under_one_gib(&["run", "--scene", scene, "--steps", "1"]);
    assert_refused(&out, &[scene, "spawn.placement"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn long_placements_are_announced_as_what_they_are() {
    // A lattice of a million circles was announced as "placing 1000000 circles at random".
    let dir = scratch_dir("hostile2", "announce");
    let cases = [
        (
            "lattice",
            "placing on a lattice 1000000 circles",
            "(size: (30.0, 30.0))",
            "count: 1000000, radius: (0.01, 0.01)",
        ),
        (
            "pack",
            "compressing 20000 circles",
            "(size: (10.0, 10.0))",
            "count: 20000, radius: (0.01, 0.02)",
        ),
    ];
    for (placement, said, arena, spawn) in cases {
        let scene = dir.join(format!("{placement}.ron"));
        let text = format!("(arena: {arena}, spawn: ({spawn}, placement: {placement}))");
        std::fs::write(&scene, text).unwrap();
        let out = under_one_gib(&["run", "--scene", scene.to_str().unwrap(), "--steps", "1"]);
        let err = stderr(&out);
        assert!(out.status.success(), "{placement}: {err}");
        assert!(err.contains(said), "{placement}: {err}");
        assert!(!err.contains("at random"), "{placement}: {err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_equation_of_state_of_too_many_disks_blames_n() {
    let dir = scratch_dir("hostile2", "eos");
    let out = under_one_gib(&[
        "eos",
        "--n",
        "18446744073709551615",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_refused(&out, &["n: needs 2 to 5000000 disks"]);
    assert!(!stderr(&out).contains("spawn.radius"), "{}", stderr(&out));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_dump_of_static_circles_reads_back_as_the_same_circles() {
    let dir = scratch_dir("hostile2", "static");
    let (first, second) = (dir.join("first.txt"), dir.join("second.txt"));
    // Pegs in the unit square (the particle format's arena): the dump writes their mass `inf`.
    let scene = dir.join("pegs.ron");
    std::fs::write(
        &scene,
        "(arena: (size: (1.0, 1.0), center: (0.5, 0.5)), \
          effects: (gravity: (0.0, -9.81), restitution: 0.5), \
          spawn: (count: 20, radius: (0.02, 0.03)), \
          circles: [(position: (0.3, 0.2), radius: 0.05, immovable: true), \
                    (position: (0.7, 0.2), radius: 0.05, immovable: true)])",
    )
    .unwrap();
    let out = under_one_gib(&[
        "run",
        "--scene",
        scene.to_str().unwrap(),
        "--steps",
        "30",
        "--dump",
        first.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let static_lines = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| l.contains(" inf "))
            .map(str::to_owned)
            .collect()
    };
    let text = std::fs::read_to_string(&first).unwrap();
    assert_eq!(
        static_lines(&text).len(),
        2,
        "the pegs in the dump:\n{text}"
    );
    // The dump is a particle file: it reads back, its static circles still static.
    let out = under_one_gib(&[
        "run",
        "--particles",
        first.to_str().unwrap(),
        "--steps",
        "1",
        "--solver",
        "exact",
        "--dump",
        second.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let again = std::fs::read_to_string(&second).unwrap();
    assert_eq!(static_lines(&text), static_lines(&again), "the pegs moved");
    // A moving static circle is still refused, naming its line.
    let moving = dir.join("moving.txt");
    std::fs::write(&moving, "1\n0.5 0.5 0.1 0 0.1 inf 0 0 0\n").unwrap();
    let out = under_one_gib(&[
        "run",
        "--particles",
        moving.to_str().unwrap(),
        "--steps",
        "1",
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("line 2") && err.contains("static"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_drop_rule_out_of_range_is_refused_by_the_run_naming_the_file_and_field() {
    let dir = scratch_dir("hostile2", "drops");
    // A subnormal radius, and a mass from the drops' own radius below the least mass.
    for (rule, field) in [
        (
            "(drop: (count: 1, radius: 5e-324, position: (0.0, 0.0)))",
            "field `drop.radius`",
        ),
        (
            "(arena: (size: (1e-3, 1e-3)), spawn: (count: 0, radius: (1e-5, 1e-5)), \
             mass: Area(density: 1e-20), drop: (count: 1, radius: 1e-6, position: (0.0, 0.0)))",
            "field `drop.radius`",
        ),
    ] {
        let scene = dir.join("drops.ron");
        std::fs::write(&scene, rule).unwrap();
        let scene = scene.to_str().unwrap();
        let out = under_one_gib(&["run", "--scene", scene, "--steps", "2"]);
        assert_refused(&out, &[scene, field]);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_circle_too_fast_for_the_clock_never_falls_asleep_outside_the_walls() {
    // Found by the checkpoint fuzz target: a heap under `swept` in which one circle flies at
    // 8.8e28 m/s. Its hits pass that speed on, and a circle crossing metres in the clock's
    // last tick fell asleep (jammed by quick hits) with its centre 0.7 m past the top wall,
    // where sleep kept it: step 2 of the resumed run ended with a circle outside.
    let dir = scratch_dir("hostile2", "too-fast");
    let report = dir.join("r.json");
    let out = crate::common::binary::moving_circles(&[
        "run",
        "--resume",
        "tests/data/checkpoints/too_fast_to_resolve.checkpoint",
        "--steps",
        "4",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).expect("report written")).unwrap();
    assert_eq!(report["escaped"], 0, "{report}");
    assert_eq!(report["non_finite"], 0, "{report}");
}

#[test]
fn a_state_past_the_range_of_values_is_not_written_as_what_our_readers_refuse() {
    // Found by the checkpoint fuzz target: 14 circles at up to 10³⁰ m/s (the edge of the
    // range), one of them 340 times lighter than the others. Hits pass it more than 10³⁰ m/s,
    // and the checkpoint of the run's end was written and then refused by our own reader.
    // Such a state is refused as a non-finite one is: nothing written, one line saying why.
    let dir = scratch_dir("hostile2", "past-range");
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let (report, dump, checkpoint) = (path("r.json"), path("d.txt"), path("c"));
    let out = crate::common::binary::moving_circles(&[
        "run",
        "--resume",
        "tests/data/checkpoints/past_the_range.checkpoint",
        "--steps",
        "1",
        "--report",
        &report,
        "--dump",
        &dump,
        "--checkpoint",
        &checkpoint,
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let said = stderr(&out);
    assert!(
        said.contains("left the range of values a file may hold"),
        "{said}"
    );
    assert!(said.contains("velocity"), "{said}");
    for written in [&report, &dump, &checkpoint] {
        assert!(
            !std::path::Path::new(written).exists(),
            "{written} was written"
        );
    }
    // A checkpoint due every step is not written either: the run stops at the first sample
    // past the range, before the checkpoint of that step (which would be checked as our reader
    // checks it, and refused).
    let out = crate::common::binary::moving_circles(&[
        "run",
        "--resume",
        "tests/data/checkpoints/past_the_range.checkpoint",
        "--steps",
        "2",
        "--checkpoint",
        &checkpoint,
        "--every",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let said = stderr(&out);
    assert!(said.contains("left the range of values"), "{said}");
    assert!(!std::path::Path::new(&checkpoint).exists(), "written");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_that_leaves_the_range_of_values_stops_at_the_first_sample_past_it() {
    // Found trying the command as a user would: a pull and a drag of 10³⁰ took the circles
    // past the range within a minute's step (such a pull is now refused up front), and the
    // run went on to its end (seconds a step at speeds past 10³⁰ under the event-driven
    // solvers) only to write nothing. Here a heavy circle at 10³⁰ m/s throws a light one past
    // it. The run stops at the sample that shows it, says which step, and writes nothing.
    let dir = scratch_dir("hostile2", "leaves-range");
    let scene = dir.join("s.ron");
    std::fs::write(
        &scene,
        "(effects: (restitution: 1.0), circles: [ \
           (position: (-2.0, 0.0), velocity: (1e30, 0.0), radius: 0.5, mass: 1e6), \
           (position: (2.0, 0.0), radius: 0.1, mass: 1e-6)])",
    )
    .unwrap();
    let report = dir.join("r.json");
    let out = crate::common::binary::moving_circles(&[
        "run",
        "--scene",
        scene.to_str().unwrap(),
        "--solver",
        "swept",
        "--dt",
        "60",
        "--steps",
        "20",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let said = stderr(&out);
    let step: u64 = said
        .split("by step ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no step named: {said}"));
    assert!(step <= 2, "ran on to step {step}: {said}");
    assert!(!report.exists(), "written");
    std::fs::remove_dir_all(&dir).unwrap();
}
