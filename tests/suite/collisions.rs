//! Pairwise collisions of the `discrete` solver: head-on swaps, oblique hits conserve momentum and
//! energy, coincident centres stay finite.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

#[test]
fn a_head_on_equal_mass_hit_swaps_velocities() {
    let mut app = create_app(CirclesConfig::default());
    let a = spawn_circle(
        &mut app,
        DVec2::new(-2.0, 0.0),
        DVec2::new(3.0, 0.0),
        0.5,
        1.0,
    );
    let b = spawn_circle(
        &mut app,
        DVec2::new(2.0, 0.0),
        DVec2::new(-1.0, 0.0),
        0.5,
        1.0,
    );
    step(&mut app, 60);
    let (_, va) = state(&app, a);
    let (_, vb) = state(&app, b);
    assert_eq!(pair_collisions(&app), 1);
    assert_eq!(
        (va, vb),
        (DVec2::new(-1.0, 0.0), DVec2::new(3.0, 0.0)),
        "velocities must swap"
    );
}

#[test]
fn an_oblique_hit_of_unequal_masses_conserves_momentum_and_energy() {
    let mut app = create_app(CirclesConfig::default());
    spawn_circle(
        &mut app,
        DVec2::new(-2.0, 0.3),
        DVec2::new(2.5, 0.2),
        0.5,
        1.0,
    );
    spawn_circle(
        &mut app,
        DVec2::new(1.0, -0.2),
        DVec2::new(-0.7, 0.4),
        0.8,
        3.7,
    );
    let (e0, p0) = energy_momentum(&mut app);
    // Momentum components can nearly cancel, so their error is judged against Σ m|v|.
    let scale: f64 = circles(&mut app).iter().map(|c| c.3 * c.1.length()).sum();
    step(&mut app, 90);
    assert_eq!(pair_collisions(&app), 1, "one hit");
    let (e1, p1) = energy_momentum(&mut app);
    // The impulse is a handful of f64 operations on O(1) values: rounding is a few ulp of f64
    // (≈1e-16 relative). 1e-12 leaves ample room for that and fails on any modelling error.
    assert_relative("kinetic energy", e1, e0, 1e-12);
    let momentum_error = (p1 - p0).length() / scale;
    assert!(
        momentum_error <= 1e-12,
        "momentum changed by {momentum_error:e} of Σ m|v|: {p0} → {p1}"
    );
    let (v0, v1) = (circles(&mut app)[0].1, circles(&mut app)[1].1);
    assert!(
        v0.y != 0.2 && v1.y != 0.4,
        "an oblique hit must turn both circles"
    );
}

#[test]
fn coincident_centres_never_produce_nan() {
    let mut app = create_app(CirclesConfig::default());
    spawn_circle(&mut app, DVec2::new(1.0, 1.0), DVec2::ZERO, 0.5, 1.0);
    spawn_circle(&mut app, DVec2::new(1.0, 1.0), DVec2::ZERO, 0.5, 1.0);
    spawn_circle(
        &mut app,
        DVec2::new(1.0, 1.0),
        DVec2::new(1.0, 1.0),
        0.3,
        2.0,
    );
    step(&mut app, 30);
    for (p, v, _, _) in circles(&mut app) {
        assert!(p.is_finite() && v.is_finite(), "non-finite state: {p} {v}");
    }
    assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
}

#[test]
fn a_crowded_box_keeps_its_energy_to_rounding_and_every_circle_inside() {
    let config = CirclesConfig {
        spawn: SpawnConfig {
            count: 400,
            radius: (0.1, 0.2),
            speed: (1.0, 3.0),
            ..default()
        },
        ..default()
    };
    let mut app = create_app(config);
    let (e0, _) = energy_momentum(&mut app);
    step(&mut app, 300);
    let collisions = pair_collisions(&app);
    assert!(collisions > 100, "a crowded box collides: {collisions}");
    let (e1, _) = energy_momentum(&mut app);
    // Elastic impulses conserve energy, even where the discrete method resolves a collision at
    // overlapped positions (measured: 4e-16 after 5 s).
    assert_relative("kinetic energy after 5 s", e1, e0, 1e-12);
    let arena = Arena::default();
    for (p, v, r, _) in circles(&mut app) {
        assert!(p.is_finite() && v.is_finite());
        assert!(arena.contains(p), "centre {p} (radius {r}) escaped");
    }
}
