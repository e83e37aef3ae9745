//! Bad input gets a clear error naming the file, the line or field, and the problem: one test
//! per kind of bad scene, and the command line's exit code and message for bad files and flags.

use std::process::Command;

use moving_circles::prelude::*;

fn scene_error(ron: &str) -> String {
    match Scene::parse(ron, "bad.ron").and_then(|s| s.to_config("bad.ron")) {
        Ok(_) => panic!("scene should have been rejected:\n{ron}"),
        Err(e) => e.to_string(),
    }
}

fn assert_starts(message: &str, expected: &str) {
    assert!(
        message.starts_with(expected),
        "\nexpected: {expected}…\n     got: {message}"
    );
}

#[test]
fn a_syntax_error_names_line_and_column() {
    assert_starts(
        &scene_error("(\n  dt: 0.1,\n  spawn: (count: 3,,),\n)"),
        "bad.ron: line 3, column",
    );
}

#[test]
fn a_byte_order_mark_is_named() {
    // Invisible in most editors; RON said only "Expected opening `(`".
    assert_starts(
        &scene_error("\u{feff}(dt: 0.01)"),
        "bad.ron: line 1: begins with a byte-order mark (U+FEFF",
    );
}

#[test]
fn an_unknown_field_is_named() {
    let e = scene_error("(\n  efects: (collisions: false),\n)");
    assert_starts(&e, "bad.ron: line 2");
    assert!(e.contains("efects"), "{e}");
}

#[test]
fn the_boundary_belongs_to_the_arena_not_the_effects() {
    // The input names `boundary`: what the test asserts is the error's pointer to its home.
    let e = scene_error("(effects: (boundary: periodic))");
    assert!(e.contains("`boundary` belongs to the arena"), "{e}");
    let e = scene_error("(arena: (size: (4.0, 4.0), gravity: (0.0, -9.81)))");
    assert!(e.contains("`gravity` belongs to the effects"), "{e}");
}

#[test]
fn a_bad_solver_is_named() {
    let e = scene_error("(solver: \"rk4\")");
    assert!(e.contains("unknown solver `rk4`"), "{e}");
}

#[test]
fn dt_must_be_positive_and_sane() {
    for dt in ["0.0", "-0.01", "1e9"] {
        assert_starts(
            &scene_error(&format!("(dt: {dt})")),
            "bad.ron: field `dt`: must be between",
        );
    }
}

#[test]
fn a_step_the_clock_cannot_count_is_refused_not_changed() {
    // The fixed clock counts whole nanoseconds: 1.5 ns would run as 2 ns (or 1), a third off.
    for dt in ["1.5e-9", "1.23456e-7"] {
        assert_starts(
            &scene_error(&format!("(dt: {dt})")),
            "bad.ron: field `dt`: the fixed clock counts whole nanoseconds",
        );
    }
    // A sixtieth of a second is 16 666 667 ns to 2e-8 of it; a whole number of nanoseconds is
    // exact.
    for dt in ["0.016666666666666666", "1e-9", "0.000123"] {
        let scene = format!("(dt: {dt}, spawn: (count: 0))");
        let config = Scene::parse(&scene, "ok.ron").and_then(|s| s.to_config("ok.ron"));
        assert!(config.is_ok(), "{dt} refused: {config:?}");
    }
}

#[test]
fn the_arena_must_have_a_positive_finite_size() {
    assert_starts(
        &scene_error("(arena: (size: (0.0, 5.0)))"),
        "bad.ron: field `arena.size`",
    );
}

#[test]
fn effect_parameters_are_checked() {
    assert_starts(
        &scene_error("(effects: (restitution: 1.5))"),
        "bad.ron: field `effects.restitution`",
    );
    assert_starts(
        &scene_error("(effects: (drag: -1.0))"),
        "bad.ron: field `effects.drag`",
    );
    for (field, value) in [
        ("friction", "-0.1"),
        ("rolling_resistance", "1e300"),
        ("tangential_restitution", "1.5"),
        ("wall_tangential_restitution", "-1.01"),
        ("tangential_restitution", "NaN"),
    ] {
        assert_starts(
            &scene_error(&format!("(effects: ({field}: {value}))")),
            &format!("bad.ron: field `effects.{field}`"),
        );
    }
    assert_starts(&scene_error("(mass: Equal(0.0))"), "bad.ron: field `mass`");
}

#[test]
fn spawn_rules_are_checked_before_anything_is_allocated() {
    assert_starts(
        &scene_error("(spawn: (count: 1000000000))"),
        "bad.ron: field `spawn.count`: asks for 1000000000",
    );
    assert_starts(
        &scene_error("(spawn: (radius: (0.5, 0.1)))"),
        "bad.ron: field `spawn.radius`",
    );
    assert_starts(
        &scene_error("(spawn: (speed: (-1.0, 1.0)))"),
        "bad.ron: field `spawn.speed`",
    );
    assert_starts(
        &scene_error("(spawn: (area_fraction: 0.95))"),
        "bad.ron: field `spawn.area_fraction`",
    );
}

#[test]
fn drop_rules_are_checked_against_the_mass_model_and_the_least_radius() {
    // Below the least radius (1e-9 of the arena's side), and a mass from the drops' own radius
    // (3e-32), not the spawn rules' (3e-30, in range).
    assert_starts(
        &scene_error("(drop: (count: 1, radius: 1e-17, position: (0.0, 0.0)))"),
        "bad.ron: field `drop.radius`: must be at least 1e-9",
    );
    assert_starts(
        &scene_error(
            "(arena: (size: (1e-3, 1e-3)), spawn: (count: 0, radius: (1e-5, 1e-5)), \
             mass: Area(density: 1e-20), drop: (count: 1, radius: 1e-6, position: (0.0, 0.0)))",
        ),
        "bad.ron: field `drop.radius`: the spawn rules' mass model gives a drop a mass that must be between",
    );
}

#[test]
fn explicit_circles_are_checked_one_by_one() {
    let circle = |fields: &str| {
        scene_error(&format!(
            "(circles: [(position: (0.0, 0.0), radius: 0.5), ({fields})])"
        ))
    };
    assert_starts(
        &circle("position: (1.0, 1.0), radius: -0.5"),
        "bad.ron: field `circles[1].radius`: must be positive",
    );
    assert_starts(
        &circle("position: (1.0, 1.0), radius: 0.5, mass: 0.0"),
        "bad.ron: field `circles[1].mass`",
    );
    assert_starts(
        &circle("position: (7.9, 1.0), radius: 0.5"),
        "bad.ron: field `circles[1].position`: (7.9, 1) with radius 0.5 is not inside",
    );
    assert_starts(
        &circle("position: (0.0, 0.0), radius: 5.0"),
        "bad.ron: field `circles[1].radius`: 5 is larger than the arena",
    );
}

#[test]
fn overlapping_circles_are_an_error_unless_separation_is_asked_for() {
    let overlap =
        "circles: [(position: (0.0, 0.0), radius: 0.5), (position: (0.6, 0.0), radius: 0.5)]";
    assert_starts(
        &scene_error(&format!("({overlap})")),
        "bad.ron: field `circles[1]`: overlaps circles[0] by",
    );
    let config = Scene::parse(&format!("(separate_overlaps: true, {overlap})"), "ok.ron")
        .and_then(|s| s.to_config("ok.ron"))
        .expect("separated");
    let [a, b] = [config.circles[0], config.circles[1]];
    assert!(a.position.distance(b.position) >= 1.0 - 1e-6, "{a:?} {b:?}");
}

#[test]
fn touching_circles_are_accepted() {
    let ok = Scene::parse(
        "(circles: [(position: (0.1, 0.0), radius: 0.1), (position: (0.3, 0.0), radius: 0.1)])",
        "t",
    )
    .and_then(|s| s.to_config("t"));
    assert!(ok.is_ok(), "{ok:?}");
}

fn cli(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_moving_circles"))
        .args(args)
        .output()
        .expect("runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_command_line_fails_cleanly_on_bad_files_and_flags() {
    let dir = std::env::temp_dir().join(format!("mc-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.txt");
    std::fs::write(
        &bad,
        "2\n0.5 0.5 0 0 0.1 1 0 0 0\n0.5 0.5 0 inf 0.1 1 0 0 0\n",
    )
    .unwrap();
    let bad = bad.to_str().unwrap();

    let (ok, err) = cli(&["run", "--particles", bad, "--steps", "10"]);
    assert!(!ok);
    assert!(
        err.contains(&format!("{bad}: line 3: vy must be finite")),
        "{err}"
    );

    let (ok, err) = cli(&["run", "--particles", "/no/such/file.txt", "--steps", "10"]);
    assert!(
        !ok && err.contains("/no/such/file.txt: cannot read"),
        "{err}"
    );

    let (ok, err) = cli(&["run", "--particles", bad, "--steps", "10", "--dt", "0"]);
    assert!(
        !ok && err.contains("--dt") && err.contains("must be between"),
        "{err}"
    );

    let (ok, err) = cli(&["run", "--particles", bad]);
    assert!(!ok && err.contains("--seconds"), "{err}");

    let (ok, err) = cli(&[
        "run",
        "--scene",
        "assets/scenes/classic.ron",
        "--steps",
        "1",
        "--boundary",
        "periodic",
    ]);
    assert!(
        !ok && err.contains("--particles"),
        "--boundary is for particle files: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");

    // A seed where no circle is placed at random would be ignored: refused, as --placement is.
    let particles = ["--particles", "tests/data/particles/p10.txt"];
    let cradle = ["--scene", "assets/scenes/cradle.ron"];
    for (input, said) in [
        (particles, "a particle file lists its own"),
        (cradle, "has none"),
    ] {
        let (ok, err) = cli(&[&["run", "--steps", "1", "--seed", "5"][..], &input].concat());
        assert!(!ok && err.contains("--seed") && err.contains(said), "{err}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_flag_out_of_its_range_gets_the_flags_rule_not_the_parsers() {
    // A negative number used to read as an unknown flag ("unexpected argument '-1'"), and an
    // out-of-range solver count did not say the range.
    let scene = ["run", "--scene", "assets/scenes/classic.ron"];
    let cases: &[(&[&str], &str)] = &[
        (&["--seconds", "-1"], "--seconds must be positive"),
        (&["--steps", "1", "--dt", "-0.01"], "must be between"),
        (&["--steps", "-5"], "from 1 to 10000000000"),
        (&["--steps", "1", "--seed", "-1"], "whole number from 0 to"),
        (
            &["--steps", "1", "--solver", "auto", "--tolerance", "-1"],
            "--tolerance must be a positive number, got -1",
        ),
        (&["--steps", "1", "--area-fraction", "-0.5"], "area"),
        (
            &["--steps", "1", "--solver", "soft=0"],
            "N from 1 to 1024, got `soft=0`",
        ),
        (
            &["--steps", "1", "--solver", "substeps=2000"],
            "N from 1 to 1024, got `substeps=2000`",
        ),
        (&["--steps", "1", "--solver", "soft=-3"], "N from 1 to 1024"),
    ];
    for (flags, said) in cases {
        let (ok, err) = cli(&[&scene[..], flags].concat());
        assert!(!ok, "{flags:?} was accepted");
        assert!(
            err.contains(said) && !err.contains("unexpected argument"),
            "{flags:?}: expected `{said}` in: {err}"
        );
    }
    let (ok, err) = cli(&["eos", "--seed", "-2", "--n", "16"]);
    assert!(!ok && err.contains("whole number from 0 to"), "{err}");
}

#[test]
fn sleep_and_drop_rules_are_checked_field_by_field() {
    let g = "gravity: (0.0, -9.81)";
    for (ron, expected) in [
        (
            format!("(effects: ({g}, sleep: (enabled: true, speed: -1.0, time: 0.5)))"),
            "bad.ron: field `effects.sleep.speed`: must be from 0 to 1e30, got -1",
        ),
        (
            format!("(effects: ({g}, sleep: (enabled: true, speed: 0.1, time: 1e40)))"),
            "bad.ron: field `effects.sleep.time`: must be from 0 to 1e30",
        ),
        (
            "(drop: (count: 3, every: -0.1, position: (0.0, 0.0), radius: 0.1))".into(),
            "bad.ron: field `drop.every`: must be a positive number of seconds, got -0.1",
        ),
        (
            "(drop: (count: 3, every: 0.1, position: (1e9, 0.0), radius: 0.1))".into(),
            "bad.ron: field `drop.position`: [1000000000, 0] ± 0 with radius 0.1 must lie inside",
        ),
        (
            "(drop: (count: 3, every: 0.1, position: (0.0, 0.0), spread: -1.0, radius: 0.1))"
                .into(),
            "bad.ron: field `drop.spread`: must be a distance of 0 or more, got -1",
        ),
        (
            "(drop: (count: 3, every: 0.1, position: (0.0, 0.0), radius: 0.1, velocity: (1e40, 0.0)))"
                .into(),
            "bad.ron: field `drop.velocity`: must be finite and at most 1e30",
        ),
        (
            "(drop: (count: 99999999999, every: 0.1, position: (0.0, 0.0), radius: 0.1))".into(),
            "bad.ron: field `drop.count`: asks for 99999999999 circles; at most 5000000",
        ),
    ] {
        assert_starts(&scene_error(&ron), expected);
    }
}
