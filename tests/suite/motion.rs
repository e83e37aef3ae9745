//! Free flight and walls: a lone circle moves exactly `v·dt` per step; a wall hit reflects it and
//! it never leaves the arena.

use crate::common::*;
use bevy::math::DVec2;
use moving_circles::prelude::*;
use moving_circles::step::schedule::StepDt;

#[test]
fn a_lone_circle_moves_exactly_v_dt_per_step() {
    let mut app = create_app(CirclesConfig::default());
    let v = DVec2::new(1.25, -0.5);
    let circle = spawn_circle(&mut app, DVec2::new(-1.0, 0.5), v, 0.3, 1.0);
    let mut expected = DVec2::new(-1.0, 0.5);
    for _ in 0..60 {
        step(&mut app, 1);
        // The fixed clock counts nanoseconds: dt is 1/60 s rounded to the nanosecond.
        let dt = app.world().resource::<StepDt>().0;
        assert!((dt - 1.0 / 60.0).abs() < 1e-9, "dt = {dt}");
        expected += v * dt;
        let (p, vel) = state(&app, circle);
        assert_eq!(p, expected, "position after one more step of dt = {dt}");
        assert_eq!(vel, v, "free flight must not change velocity");
    }
}

#[test]
fn substeps_cover_the_same_time() {
    let config = CirclesConfig {
        solver: Solver::Substeps(4),
        ..CirclesConfig::default()
    };
    let mut app = create_app(config);
    let circle = spawn_circle(&mut app, DVec2::ZERO, DVec2::new(2.0, 0.0), 0.3, 1.0);
    step(&mut app, 30);
    let (p, _) = state(&app, circle);
    // 4 × 30 additions of 2 · dt/4 in f64: half a second of flight, up to rounding.
    assert!(
        (p.x - 1.0).abs() < 1e-5,
        "expected x = 1.0 after 0.5 s, got {}",
        p.x
    );
}

#[test]
fn a_wall_hit_reflects_and_stays_inside() {
    let arena = Arena::default();
    let mut app = create_app(CirclesConfig::default());
    let r = 0.4;
    let v = DVec2::new(6.0, 1.5);
    let circle = spawn_circle(&mut app, DVec2::new(arena.max.x - 1.0, 0.0), v, r, 1.0);
    let mut reflected = false;
    for _ in 0..600 {
        step(&mut app, 1);
        let (p, vel) = state(&app, circle);
        assert_inside(&arena, p, r, "the circle");
        assert_eq!(vel.abs(), v.abs(), "walls only flip velocity components");
        reflected |= vel.x < 0.0;
    }
    assert!(reflected, "the circle never bounced off the right wall");
    assert!(wall_collisions(&app) > 0);
}
