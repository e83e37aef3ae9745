//! Dense states on request: a triangular lattice fills any area fraction up to 0.85 (random
//! placement stalls near 0.5), from a scene and from the command line, and the exact solver
//! melts it with no overlap and energy kept to rounding.

use std::process::Command;

use crate::common::{area_fraction, create_app, dense_config, energy_momentum, scene_app, step};
use bevy::math::DVec2;
use moving_circles::base::circle::{discs, snapshot};
use moving_circles::game::spawn::place_circles;
use moving_circles::kernels::Overlaps;
use moving_circles::prelude::*;

/// A unit box asked for `fraction` of circles of radius `r` on a lattice.
fn lattice_config(fraction: f64, r: f64, boundary: Boundary) -> CirclesConfig {
    dense_config(fraction, (r, r), boundary, Placement::Lattice)
}

#[test]
fn a_lattice_fills_area_fraction_0_85_with_no_overlap() {
    for boundary in [Boundary::Periodic, Boundary::Walls] {
        let config = lattice_config(0.85, 0.008, boundary);
        let circles = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
        let wanted = config.spawn.target_count(&config.arena);
        assert_eq!(circles.len(), wanted, "{boundary:?}: every circle placed");
        let fraction = area_fraction(&circles, &config.arena);
        assert!((fraction - 0.85).abs() < 1e-3, "{boundary:?}: {fraction}");
        let overlaps = Overlaps::measure(&discs(&circles), &config.arena, &[]);
        assert_eq!(overlaps.pairs, 0, "{boundary:?}: {overlaps:?}");
        for c in &circles {
            let inside = match boundary {
                Boundary::Periodic => config.arena.contains(c.position),
                Boundary::Walls | Boundary::Open => {
                    let r = DVec2::splat(c.radius);
                    let (lo, hi) = (config.arena.min + r, config.arena.max - r);
                    c.position.cmpge(lo).all() && c.position.cmple(hi).all()
                }
            };
            assert!(inside, "{boundary:?}: {} outside", c.position);
        }
        // Seeded: the same rules give the same circles, another seed other sites.
        let again = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
        assert_eq!(circles, again);
        let mut other = config.spawn.clone();
        other.seed += 1;
        let elsewhere = place_circles(&config.arena, &other, &[], &[]).unwrap();
        assert_eq!(elsewhere.len(), circles.len());
        assert_ne!(
            elsewhere, circles,
            "{boundary:?}: another seed, the same sites"
        );
    }
}

#[test]
fn random_placement_cannot_reach_what_the_lattice_does() {
    // The reason the lattice exists: random placement gives up well short of 0.7.
    let mut config = lattice_config(0.7, 0.01, Boundary::Periodic);
    config.spawn.placement = Placement::Random;
    let random = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
    assert!(area_fraction(&random, &config.arena) < 0.6);
    config.spawn.placement = Placement::Lattice;
    let lattice = place_circles(&config.arena, &config.spawn, &[], &[]).unwrap();
    assert!((area_fraction(&lattice, &config.arena) - 0.7).abs() < 2e-3);
}

#[test]
fn the_exact_solver_melts_a_lattice_at_0_85_with_no_overlap_and_energy_kept() {
    let mut app = create_app(lattice_config(0.85, 0.012, Boundary::Periodic));
    let (e0, p0) = energy_momentum(&mut app);
    let arena = Arena::unit_square(Boundary::Periodic);
    let start = snapshot(app.world_mut());
    for _ in 0..20 {
        step(&mut app, 5);
        let circles = snapshot(app.world_mut());
        let overlaps = Overlaps::measure(&discs(&circles), &arena, &[]);
        assert!(overlaps.max < 1e-9, "{overlaps:?}");
    }
    let (e1, p1) = energy_momentum(&mut app);
    assert!(((e1 - e0) / e0).abs() < 1e-12, "energy {e0} -> {e1}");
    assert!(
        (p1 - p0).length() < 1e-9 * e0.sqrt(),
        "momentum {p0} -> {p1}"
    );
    // It really ran: many collisions, and the circles left their sites.
    let collisions = app.world().resource::<PairCollisions>().count;
    assert!(
        collisions > 10 * start.len() as u64,
        "{collisions} collisions"
    );
    let moved = snapshot(app.world_mut())
        .iter()
        .zip(&start)
        .filter(|(now, then)| arena.offset(now.position, then.position).length() > 0.012)
        .count();
    assert!(
        moved > start.len() / 10,
        "only {moved} circles left their site"
    );
}

#[test]
fn a_lattice_too_dense_for_the_arena_is_refused_with_how_dense_it_can_be() {
    // Walls cost the lattice a border of half-empty rows: 0.9 does not fit in a unit box.
    let config = lattice_config(0.9, 0.01, Boundary::Walls);
    let error = place_circles(&config.arena, &config.spawn, &[], &[])
        .unwrap_err()
        .to_string();
    assert!(error.contains("spawn.area_fraction"), "{error}");
    assert!(error.contains("does not fit"), "{error}");
    assert!(error.contains("area fraction 0.8"), "{error}");
}

#[test]
fn a_lattice_of_unequal_radii_is_refused_naming_the_field() {
    let mut config = lattice_config(0.5, 0.01, Boundary::Periodic);
    config.spawn.radius = (0.01, 0.02);
    let error = config.check().unwrap_err().to_string();
    assert!(error.contains("spawn.radius"), "{error}");
    assert!(error.contains("one radius"), "{error}");
}

#[test]
fn a_scene_asks_for_a_lattice() {
    let mut app = scene_app(
        "(arena: (size: (1.0, 1.0), boundary: periodic), solver: \"exact\", \
          spawn: (placement: lattice, area_fraction: 0.8, radius: (0.01, 0.01)))",
    );
    let circles = snapshot(app.world_mut());
    let fraction = area_fraction(&circles, &Arena::unit_square(Boundary::Periodic));
    assert!((fraction - 0.8).abs() < 2e-3, "{fraction}");
}

#[test]
fn the_command_line_asks_for_a_lattice_and_refuses_it_for_particle_files() {
    let dir = std::env::temp_dir().join(format!("mc-dense-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("box.ron");
    std::fs::write(
        &scene,
        "(arena: (size: (1.0, 1.0), boundary: periodic), spawn: (radius: (0.01, 0.01)))",
    )
    .unwrap();
    let report = dir.join("report.json");
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_moving_circles"))
            .args(["run", "--solver", "exact", "--steps", "20", "--dt", "0.01"])
            .args(extra)
            .output()
            .unwrap()
    };
    let scene_arg = scene.to_str().unwrap();
    let out = run(&[
        "--scene",
        scene_arg,
        "--placement",
        "lattice",
        "--area-fraction",
        "0.82",
        "--report",
        report.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&report).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(json["n"], 2610, "{text}"); // 0.82 / (π 0.01²)
    assert_eq!(json["max_penetration"], 0.0, "{text}");

    let out = run(&["--scene", scene_arg, "--placement", "hexagonal"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && stderr.contains("expected `random`, `lattice` or `pack`"));

    let particles = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/particles/p10.txt");
    let out = run(&["--particles", particles, "--placement", "lattice"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("a particle file lists its own"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
