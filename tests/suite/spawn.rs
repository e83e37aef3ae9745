//! Spawning: no overlaps, everything inside, reproducible from the seed, and the whole
//! simulation is deterministic for a seed.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::game::spawn::place_circles;
use moving_circles::prelude::*;

fn assert_valid_placement(arena: &Arena, placed: &[(DVec2, f64)]) {
    for (i, &(p, r)) in placed.iter().enumerate() {
        assert_inside(arena, p, r, &format!("circle {i}"));
        for (j, &(q, s)) in placed.iter().enumerate().skip(i + 1) {
            assert!(
                p.distance(q) >= r + s,
                "circles {i} and {j} overlap: {p} r {r}, {q} r {s}"
            );
        }
    }
}

#[test]
fn spawned_circles_never_overlap_and_stay_inside() {
    let config = CirclesConfig {
        spawn: SpawnConfig {
            count: 1500,
            radius: (0.02, 0.15),
            seed: 99,
            ..default()
        },
        ..default()
    };
    let mut app = create_app(config.clone());
    let placed: Vec<_> = circles(&mut app)
        .iter()
        .map(|&(p, _, r, _)| (p, r))
        .collect();
    assert_eq!(placed.len(), 1500, "this arena has room for all of them");
    assert_valid_placement(&config.arena, &placed);
    let report = app.world().resource::<SpawnReport>().clone();
    assert_eq!((report.requested, report.placed), (1500, 1500));
}

#[test]
fn an_overfull_request_places_what_fits_and_reports_it() {
    let arena = Arena::centered(DVec2::new(4.0, 3.0));
    let spawn = SpawnConfig {
        count: 5000,
        radius: (0.2, 0.3),
        ..default()
    };
    let config = CirclesConfig {
        arena,
        spawn,
        ..default()
    };
    let mut app = create_app(config);
    let report = app.world().resource::<SpawnReport>().clone();
    assert_eq!(report.requested, 5000);
    assert!(
        report.placed > 10 && report.placed < 100,
        "placed {}",
        report.placed
    );
    let placed: Vec<_> = circles(&mut app)
        .iter()
        .map(|&(p, _, r, _)| (p, r))
        .collect();
    assert_eq!(placed.len(), report.placed);
    assert_valid_placement(&arena, &placed);
}

#[test]
fn the_same_seed_places_the_same_circles_and_another_seed_does_not() {
    let arena = Arena::default();
    let spawn = moving_circles::tools::scene::classic().spawn;
    let a = place_circles(&arena, &spawn, &[], &[]).unwrap();
    let b = place_circles(&arena, &spawn, &[], &[]).unwrap();
    let c = place_circles(
        &arena,
        &SpawnConfig {
            seed: 2,
            ..spawn.clone()
        },
        &[],
        &[],
    )
    .unwrap();
    assert_eq!(a, b);
    assert_ne!(a, c);
}

#[test]
fn the_same_seed_gives_the_same_state_after_600_steps() {
    let run = |seed| {
        let config = CirclesConfig {
            spawn: SpawnConfig {
                count: 200,
                radius: (0.1, 0.3),
                seed,
                ..default()
            },
            ..default()
        };
        let mut app = create_app(config);
        step(&mut app, 600);
        assert!(pair_collisions(&app) > 0);
        state_hash(&mut app)
    };
    let first = run(5);
    assert_eq!(
        first,
        run(5),
        "same seed, different final state: the step is not deterministic"
    );
    assert_ne!(
        first,
        run(6),
        "a different seed should give a different final state"
    );
}

#[test]
fn a_respawn_replaces_every_circle() {
    let mut app = create_app(moving_circles::tools::scene::classic());
    step(&mut app, 10);
    app.world_mut().resource_mut::<SpawnConfig>().count = 7;
    app.world_mut().write_message(Respawn);
    app.update();
    assert_eq!(circles(&mut app).len(), 7);
    assert_eq!(app.world().resource::<CircleDiagnostics>().count, 7);
}
