//! What circles dropped in while a run goes on bring with them: the report counts their energy
//! and momentum as added (`energy_added`, `momentum_added`), so that `energy_drift` measures
//! what the solver changed, not what came in; the same in the HUD's drift and through a resume.

use crate::common::binary::{read_report as report, scratch_dir, successful};
use crate::common::{scene_app, step};
use moving_circles::prelude::*;

/// Elastic balls dropped into an empty box under gravity, one every 0.1 s: nothing but the
/// solver can change the energy once they are in.
const ELASTIC_DROPS: &str = r#"(
    arena: (size: (4.0, 6.0), boundary: walls),
    effects: (
        collisions: true,
        gravity: (0.0, -9.81),
        restitution: 1.0,
        wall_restitution: 1.0,
    ),
    solver: "exact",
    spawn: (count: 0),
    drop: (count: 12, every: 0.1, position: (0.0, 2.5), spread: 1.5, radius: 0.1,
           velocity: (0.7, -1.0), seed: 3),
)"#;

#[test]
fn the_report_counts_what_drops_bring_in() {
    let dir = scratch_dir("drops", "report");
    let scene = dir.join("drops.ron");
    std::fs::write(&scene, ELASTIC_DROPS).unwrap();
    let (scene, whole, first, rest, checkpoint) = (
        scene.to_str().unwrap().to_owned(),
        dir.join("whole.json"),
        dir.join("first.json"),
        dir.join("rest.json"),
        dir.join("half.checkpoint"),
    );
    let path = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    successful(&[
        "run",
        "--scene",
        &scene,
        "--steps",
        "180",
        "--report",
        &path(&whole),
    ]);
    let r = report(&whole);
    assert_eq!(r["n"], 12, "{r}");
    assert_eq!(r["energy_initial"], 0.0, "{r}");
    let added = r["energy_added"].as_f64().unwrap();
    assert!(added > 0.0, "{r}");
    // Before the drops were counted the drift was the whole energy of 12 balls (from nothing).
    let drift = r["energy_drift"].as_f64().unwrap();
    assert!(
        drift.abs() < 1e-12,
        "energy drift {drift:e} with drops counted: {r}"
    );
    // Every ball came in at (0.7, -1.0).
    let momentum: Vec<f64> = (0..2)
        .map(|i| r["momentum_added"][i].as_f64().unwrap())
        .collect();
    assert!(momentum[0] > 0.0, "{r}");
    assert!(
        (momentum[1] + momentum[0] / 0.7).abs() < 1e-12 * momentum[0],
        "{r}"
    );

    // Split at a step between two drops: the second half counts only what the first had not.
    successful(&[
        "run",
        "--scene",
        &scene,
        "--steps",
        "100",
        "--report",
        &path(&first),
        "--checkpoint",
        &path(&checkpoint),
    ]);
    successful(&[
        "run",
        "--resume",
        &path(&checkpoint),
        "--steps",
        "80",
        "--report",
        &path(&rest),
    ]);
    let rest = report(&rest);
    assert_eq!(rest["energy_added"], r["energy_added"], "{rest}");
    assert_eq!(rest["energy_drift"], r["energy_drift"], "{rest}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_huds_drift_counts_what_drops_bring_in() {
    let mut app = scene_app(ELASTIC_DROPS);
    step(&mut app, 150);
    let d = app.world().resource::<CircleDiagnostics>();
    assert_eq!(d.count, 12);
    assert!(d.added_energy > 0.0);
    assert!(d.energy_drift().abs() < 1e-12, "{}", d.energy_drift());
}
