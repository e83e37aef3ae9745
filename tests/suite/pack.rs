//! The `pack` placement: a Lubachevsky–Stillinger compression under the event engine fills an
//! arena to area fraction 0.85 with any radii, walled or periodic, from a scene and from the
//! command line; a request past jamming is refused, in bounded time, saying how far it got.

use std::process::Command;

use crate::common::{area_fraction, create_app, dense_config, energy_momentum, scene_app, step};
use bevy::math::DVec2;
use moving_circles::base::circle::{discs, snapshot};
use moving_circles::game::spawn::place_circles;
use moving_circles::kernels::Overlaps;
use moving_circles::prelude::*;

/// A unit box asked for `fraction` of circles of radii `radius`, compressed.
fn pack_config(fraction: f64, radius: (f64, f64), boundary: Boundary) -> CirclesConfig {
    dense_config(fraction, radius, boundary, Placement::Pack)
}

/// No two circles overlap by more than rounding, and with walls every circle is inside them.
fn assert_packed(circles: &[CircleState], arena: &Arena, what: &str) {
    let overlaps = Overlaps::measure(&discs(circles), arena, &[]);
    assert!(overlaps.max < 1e-12, "{what}: {overlaps:?}");
    for c in circles {
        let inside = if arena.is_periodic() {
            arena.contains(c.position)
        } else {
            let r = DVec2::splat(c.radius * (1.0 - 1e-12));
            c.position.cmpge(arena.min + r).all() && c.position.cmple(arena.max - r).all()
        };
        assert!(
            inside,
            "{what}: {} (radius {}) outside",
            c.position, c.radius
        );
    }
}

#[test]
fn a_compression_packs_equal_disks_to_0_85_walled_or_periodic() {
    for boundary in [Boundary::Periodic, Boundary::Walls] {
        let config = pack_config(0.85, (0.02, 0.02), boundary);
        let circles = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
        let what = format!("{boundary:?}");
        assert_eq!(
            circles.len(),
            config.spawn.target_count(&config.arena),
            "{what}"
        );
        let fraction = area_fraction(&circles, &config.arena);
        assert!((fraction - 0.85).abs() < 1e-3, "{what}: {fraction}");
        assert_packed(&circles, &config.arena, &what);
        // The radii and speeds asked for, whatever the compression did to them.
        for c in &circles {
            assert_eq!(c.radius, 0.02, "{what}");
            let speed = c.velocity.length();
            assert!(
                (0.5 - 1e-12..=2.0 + 1e-12).contains(&speed),
                "{what}: {speed}"
            );
        }
        let again = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
        assert_eq!(circles, again, "{what}: seeded");
    }
}

#[test]
fn a_compression_packs_radii_of_a_threefold_range() {
    let config = pack_config(0.8, (0.01, 0.03), Boundary::Walls);
    let circles = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
    assert_eq!(circles.len(), config.spawn.target_count(&config.arena));
    let fraction = area_fraction(&circles, &config.arena);
    assert!((fraction - 0.8).abs() < 0.03, "{fraction}");
    assert_packed(&circles, &config.arena, "polydisperse");
    assert!(circles.iter().all(|c| (0.01..=0.03).contains(&c.radius)));
    // Past what random placement reaches with these radii.
    let mut random = config.clone();
    random.spawn.placement = Placement::Random;
    let loose = place_circles(&random.arena, &random.spawn, &[], &[]).unwrap();
    let reached = area_fraction(&loose, &random.arena);
    assert!(reached < 0.75, "random placement reached {reached}");
}

#[test]
fn the_exact_solver_runs_a_packed_state_with_no_overlap_and_energy_kept() {
    let config = pack_config(0.85, (0.015, 0.015), Boundary::Periodic);
    let arena = config.arena;
    let mut app = create_app(config);
    let (e0, _) = energy_momentum(&mut app);
    let start = snapshot(app.world_mut()).len();
    for _ in 0..10 {
        step(&mut app, 5);
        let circles = snapshot(app.world_mut());
        assert_packed(&circles, &arena, "running");
    }
    let (e1, _) = energy_momentum(&mut app);
    assert!(((e1 - e0) / e0).abs() < 1e-12, "energy {e0} -> {e1}");
    let collisions = app.world().resource::<PairCollisions>().count;
    assert!(collisions > 10 * start as u64, "{collisions} collisions");
}

#[test]
fn a_compression_past_jamming_is_refused_saying_how_far_it_got() {
    // Equal disks cannot pass 0.907; this one jams on the way.
    let config = pack_config(0.9, (0.04, 0.04), Boundary::Periodic);
    let error = place_circles(&config.arena, &config.spawn, &[], &[])
        .unwrap_err()
        .to_string();
    assert!(error.contains("spawn.area_fraction"), "{error}");
    assert!(error.contains("jammed at 0.8"), "{error}");
}

#[test]
fn a_compression_of_more_circles_than_it_takes_is_refused_before_any_work() {
    // 0.5 of a unit box in circles of radius 1e-3 is 159 155 circles: past the limit.
    let config = pack_config(0.5, (1e-3, 1e-3), Boundary::Periodic);
    let error = config.check().unwrap_err().to_string();
    assert!(error.contains("spawn.count"), "{error}");
    assert!(error.contains("at most 100000"), "{error}");
}

#[test]
fn a_compression_around_fixed_circles_or_segment_walls_is_refused() {
    let config = pack_config(0.5, (0.02, 0.02), Boundary::Walls);
    let fixed = [CircleState::new(DVec2::splat(0.5), DVec2::ZERO, 0.1)];
    let error = place_circles(&config.arena, &config.spawn, &fixed, &[])
        .unwrap_err()
        .to_string();
    assert!(error.contains("spawn.placement"), "{error}");
    assert!(error.contains("fixed circles and segment walls"), "{error}");
}

#[test]
fn a_scene_and_the_command_line_ask_for_a_compression() {
    let mut app = scene_app(
        "(arena: (size: (1.0, 1.0), boundary: periodic), solver: \"exact\", \
          spawn: (placement: pack, area_fraction: 0.8, radius: (0.02, 0.02)))",
    );
    let circles = snapshot(app.world_mut());
    let arena = Arena::centered(DVec2::ONE).with_boundary(Boundary::Periodic);
    assert!((area_fraction(&circles, &arena) - 0.8).abs() < 2e-3);
    assert_packed(&circles, &arena, "scene");

    let dir = std::env::temp_dir().join(format!("mc-pack-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("box.ron");
    std::fs::write(
        &scene,
        "(arena: (size: (1.0, 1.0), boundary: periodic), spawn: (radius: (0.03, 0.03)))",
    )
    .unwrap();
    let report = dir.join("report.json");
    let run = |fraction: &str| {
        Command::new(env!("CARGO_BIN_EXE_moving_circles"))
            .args(["run", "--solver", "exact", "--steps", "20", "--dt", "0.01"])
            .args(["--scene", scene.to_str().unwrap(), "--placement", "pack"])
            .args([
                "--area-fraction",
                fraction,
                "--report",
                report.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let out = run("0.85");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["n"], 301, "{json}"); // 0.85 / (π 0.03²)
    assert_eq!(json["max_penetration"], 0.0, "{json}");
    std::fs::remove_file(&report).unwrap();
    // Jammed: an error naming the field, and no report.
    let out = run("0.9");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("jammed"),
        "{stderr}"
    );
    assert!(!report.exists());
    std::fs::remove_dir_all(&dir).ok();
}
