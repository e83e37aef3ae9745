//! Hostile and clumsy input, second campaign, through the real binary: arenas of extreme
//! shape run in bounded memory, flags out of range are usage errors (exit 2), and every
//! refusal names what it refuses.
#![cfg(unix)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// `moving_circles` under a 1 GiB address-space limit (as in `tests/hostile.rs`).
fn under_one_gib(args: &[&str]) -> Output {
    let binary = env!("CARGO_BIN_EXE_moving_circles");
    Command::new("sh")
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("DISPLAY", "")
        .arg("-c")
        .arg(r#"ulimit -v 1048576 && exec "$0" "$@""#)
        .arg(binary)
        .args(args)
        .output()
        .expect("runs")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mc-hostile2-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn a_long_thin_arena_runs_in_bounded_memory() {
    let dir = temp_dir("thin");
    // One side 10^18, the other 9: the placement grid once asked for a row of 1.9·10^9 cells.
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
            let out = under_one_gib(&["run", "--scene", scene.to_str().unwrap(), "--steps", "2"]);
            assert!(out.status.success(), "{boundary} {size}: {}", stderr(&out));
        }
    }
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
    let dir = temp_dir("pack");
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
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains(scene) && err.contains("spawn.placement"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_equation_of_state_of_too_many_disks_blames_n() {
    let dir = temp_dir("eos");
    let out = under_one_gib(&[
        "eos",
        "--n",
        "18446744073709551615",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("n: needs 2 to 5000000 disks"), "{err}");
    assert!(!err.contains("spawn.radius"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
