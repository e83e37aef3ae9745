//! The four solvers keep their promises: `exact` conserves energy to 1e-9 over 100 s of a
//! 1000-circle gas and `swept` to 1e-6; fast circles do not tunnel under `swept` and `exact`
//! (and do under `discrete`); Newton's cradle comes out right under `exact`; the `exact`
//! engine persists across steps; solvers can be switched mid-run.

mod common;

use bevy::math::DVec2;
use bevy::prelude::*;
use common::*;
use moving_circles::exact::EngineState;
use moving_circles::prelude::*;

fn gas_1000(solver: Solver) -> App {
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(10.4, 5.85)),
        spawn: SpawnConfig {
            area_fraction: Some(0.3),
            radius: (0.05, 0.1),
            speed: (0.5, 2.0),
            seed: 11,
            ..default()
        },
        solver,
        ..default()
    };
    create_app(config)
}

fn drift_over_100_seconds(solver: Solver) -> (f64, u64) {
    let mut app = gas_1000(solver);
    let n = circles(&mut app).len();
    assert!((950..=1050).contains(&n), "{n} circles");
    let (e0, _) = energy_momentum(&mut app);
    step(&mut app, 6000);
    let (e1, _) = energy_momentum(&mut app);
    assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
    assert_eq!(app.world().resource::<CircleDiagnostics>().escaped, 0);
    ((e1 - e0).abs() / e0, pair_collisions(&app))
}

#[test]
fn exact_conserves_energy_to_1e9_over_100_seconds_of_a_1000_circle_gas() {
    let (drift, collisions) = drift_over_100_seconds(Solver::Exact);
    assert!(
        collisions > 20_000,
        "tens of thousands of collisions expected, got {collisions}"
    );
    assert!(drift < 1e-9, "relative energy drift {drift:e}");
}

#[test]
fn swept_conserves_energy_to_1e6_over_100_seconds_of_a_1000_circle_gas() {
    let (drift, collisions) = drift_over_100_seconds(Solver::Swept);
    assert!(collisions > 20_000, "{collisions}");
    assert!(drift < 1e-6, "relative energy drift {drift:e}");
}

/// Two circles of radius 0.01 closing at 8 diameters per step (0.16 per step at 60 Hz).
fn fast_pair(solver: Solver) -> (u64, Vec<(DVec2, DVec2, f64, f64)>) {
    let mut app = create_app(empty(CirclesConfig {
        solver,
        ..default()
    }));
    spawn_head_on(&mut app, 1.0, 4.8, 0.01);
    step(&mut app, 20);
    (pair_collisions(&app), circles(&mut app))
}

#[test]
fn fast_circles_collide_under_swept_and_exact() {
    for solver in [Solver::Swept, Solver::Exact] {
        let (hits, cs) = fast_pair(solver);
        assert_eq!(hits, 1, "{solver}: the pair must collide once");
        assert!(
            cs[0].1.x < 0.0 && cs[1].1.x > 0.0,
            "{solver}: they bounce back: {cs:?}"
        );
        assert!(
            cs[0].0.x < cs[1].0.x,
            "{solver}: and never pass through each other"
        );
    }
}

#[test]
fn fast_circles_tunnel_under_discrete() {
    // What `discrete` does not promise: the closing speed skips over the contact.
    let (hits, cs) = fast_pair(Solver::Discrete);
    assert_eq!(hits, 0);
    assert!(
        cs[0].0.x > cs[1].0.x,
        "they passed through each other: {cs:?}"
    );
}

#[test]
fn newtons_cradle_sends_the_last_circle_off_at_the_strikers_speed_under_exact() {
    let mut app = create_app(
        Scene::load(std::path::Path::new("assets/scenes/cradle.ron"))
            .map(|c| CirclesConfig {
                solver: Solver::Exact,
                ..c
            })
            .unwrap(),
    );
    step(&mut app, 90);
    let cs = circles(&mut app);
    let striker_speed = 2.0;
    // Row circles are spawned first (indices 0..5 at x = 0..4), the striker last.
    for (i, c) in cs.iter().enumerate().take(4) {
        assert!(
            c.1.length() < 1e-12,
            "row circle {i} should be at rest, has {}",
            c.1
        );
    }
    assert!(
        cs[5].1.length() < 1e-12,
        "the striker should be at rest, has {}",
        cs[5].1
    );
    assert!(
        (cs[4].1 - DVec2::new(striker_speed, 0.0)).length() < 1e-12,
        "last circle: {}",
        cs[4].1
    );
}

#[test]
fn the_exact_engine_persists_across_steps() {
    let mut app = gas_1000(Solver::Exact);
    step(&mut app, 120);
    assert_eq!(
        app.world().resource::<EngineState>().rebuilds,
        1,
        "built once, then kept"
    );
    let mut app = gas_1000(Solver::Swept);
    step(&mut app, 120);
    assert_eq!(
        app.world().resource::<EngineState>().rebuilds,
        120,
        "swept starts afresh every step"
    );
}

#[test]
fn solvers_can_be_switched_mid_run() {
    let mut app = gas_1000(Solver::Discrete);
    step(&mut app, 30);
    let (e0, _) = energy_momentum(&mut app);
    for solver in [
        Solver::Exact,
        Solver::Swept,
        Solver::Substeps(4),
        Solver::Exact,
    ] {
        *app.world_mut().resource_mut::<Solver>() = solver;
        step(&mut app, 30);
    }
    let (e1, _) = energy_momentum(&mut app);
    assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
    assert_relative("energy across solver switches", e1, e0, 0.05);
}
