//! The example scenes and particle files: each loads, runs, and schedules what it calls for;
//! a scene applied at runtime (hot reload) swaps the effect systems.

use std::path::{Path, PathBuf};

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::tools::scene::{asset::apply_config, particles};

fn scene_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(format!("{name}.ron"))
}

/// Every scene in `assets/scenes/`, by name.
fn example_scenes() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "ron"))
        .map(|path| path.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn every_example_scene_loads_and_runs_clean() {
    let names = example_scenes();
    assert!(names.len() >= 9, "the scenes folder holds {names:?}");
    for name in names {
        let config = Scene::load(&scene_path(&name)).unwrap_or_else(|e| panic!("{e}"));
        let mut app = create_app(config);
        step(&mut app, 20);
        let d = *app.world().resource::<CircleDiagnostics>();
        assert!(d.count > 0, "{name}: no circles");
        assert_eq!((d.non_finite, d.escaped), (0, 0), "{name}: {d:?}");
    }
}

#[test]
fn the_app_default_is_the_classic_scene_file() {
    let from_file = Scene::load(&scene_path("classic")).unwrap();
    assert_eq!(moving_circles::tools::scene::classic(), from_file);
    assert_eq!(from_file.spawn.count, 32);
    assert_eq!(from_file.spawn.mass, MassModel::Equal(1.0));
    assert_eq!(from_file.arena.size(), DVec2::new(16.0, 9.0));
}

#[test]
fn each_scene_schedules_exactly_its_effects() {
    let expect = |name: &str, present: &[&str], absent: &[&str]| {
        let mut app = create_app(Scene::load(&scene_path(name)).unwrap());
        for system in present {
            assert_scheduled(&mut app, system, true);
        }
        for system in absent {
            assert_scheduled(&mut app, system, false);
        }
    };
    let all = [
        "apply_gravity",
        "apply_drag",
        "bounce_off_walls",
        "wrap_around",
        "collide_circles",
    ];
    let others = |present: &[&'static str]| -> Vec<&'static str> {
        all.iter()
            .copied()
            .filter(|s| !present.contains(s))
            .collect()
    };
    for (name, present) in [
        ("drift", vec!["bounce_off_walls"]),
        ("gas", vec!["wrap_around", "collide_circles"]),
        (
            "gravity",
            vec!["apply_gravity", "bounce_off_walls", "collide_circles"],
        ),
        ("classic", vec!["bounce_off_walls", "collide_circles"]),
    ] {
        expect(name, &present, &others(&present));
    }
}

#[test]
fn the_gas_scene_is_ten_thousand_circles_at_three_tenths() {
    let config = Scene::load(&scene_path("gas")).unwrap();
    let mut app = create_app(config.clone());
    let n = circles(&mut app).len();
    assert!((9_500..=10_500).contains(&n), "{n} circles");
    let area: f64 = circles(&mut app)
        .iter()
        .map(|c| std::f64::consts::PI * c.2 * c.2)
        .sum();
    assert!(
        (area / config.arena.area() - 0.3).abs() < 0.01,
        "area fraction {}",
        area / config.arena.area()
    );
}

#[test]
fn applying_another_scene_at_runtime_swaps_the_effect_systems() {
    let mut app = create_app(Scene::load(&scene_path("drift")).unwrap());
    assert_scheduled(&mut app, "collide_circles", false);
    let gas = Scene::load(&scene_path("gas")).unwrap();
    apply_config(app.world_mut(), &gas);
    app.update(); // the respawn runs in PreUpdate
    assert_scheduled(&mut app, "collide_circles", true);
    assert_scheduled(&mut app, "wrap_around", true);
    assert_scheduled(&mut app, "bounce_off_walls", false);
    step(&mut app, 5);
    assert!(pair_collisions(&app) > 0, "the new systems run");
    assert!(circles(&mut app).len() > 9_000);

    apply_config(app.world_mut(), &Scene::load(&scene_path("drift")).unwrap());
    app.update();
    assert_scheduled(&mut app, "collide_circles", false);
    assert_scheduled(&mut app, "bounce_off_walls", true);
    step(&mut app, 5);
    assert_eq!(pair_collisions(&app), 0);
}

#[test]
fn the_sample_particle_files_load_exactly() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/particles");
    for (file, n) in [
        ("billiards5.txt", 16),
        ("wallbouncing.txt", 18),
        ("diagonal.txt", 2),
        ("p10.txt", 10),
        ("brownian.txt", 1000),
    ] {
        let circles =
            particles::read(&dir.join(file), Boundary::Walls).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(circles.len(), n, "{file}");
        // Writing and reading back gives the same circles (f64 shortest round-trip decimals).
        let again = particles::parse(&particles::format(&circles), file, Boundary::Walls).unwrap();
        assert_eq!(again, circles, "{file}");
    }
    let brownian = particles::read(&dir.join("brownian.txt"), Boundary::Walls).unwrap();
    assert_eq!((brownian[0].radius, brownian[0].mass), (0.1, 1.0));
    assert_eq!(brownian[0].tint, [17, 247, 236]);
}

#[test]
fn a_mass_inside_spawn_is_refused_not_overwritten_by_the_top_level_one() {
    // The top-level `mass` gives spawned circles their masses; one inside `spawn` used to be
    // read and then silently replaced by it.
    let text = "(mass: Equal(2.0), spawn: (count: 3, mass: Equal(5.0)))";
    let error = Scene::parse(text, "two_masses.ron")
        .unwrap_err()
        .to_string();
    assert!(error.contains("two_masses.ron"), "{error}");
    assert!(error.contains("`mass`"), "{error}");
    assert!(error.contains("top level"), "{error}");
    let config = Scene::parse("(mass: Equal(2.0), spawn: (count: 3))", "s.ron")
        .unwrap()
        .to_config("s.ron")
        .unwrap();
    assert_eq!(config.spawn.mass, MassModel::Equal(2.0));
}
