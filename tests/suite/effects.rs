//! One test per effect: it acts when the scene asks for it, and it has no system (and no
//! effect) when the scene does not.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;

fn one_circle(effects: &str, boundary: &str, position: &str, velocity: &str) -> App {
    one_circle_under("discrete", effects, boundary, position, velocity)
}

fn one_circle_under(
    solver: &str,
    effects: &str,
    boundary: &str,
    position: &str,
    velocity: &str,
) -> App {
    scene_app(&format!(
        "(solver: \"{solver}\", arena: (size: (10.0, 10.0), boundary: {boundary}),
          effects: ({effects}), circles: [(position: {position}, velocity: {velocity}, radius: 0.5)])"
    ))
}

fn first_state(app: &mut App) -> (DVec2, DVec2) {
    let c = circles(app)[0];
    (c.0, c.1)
}

/// Checks that `system` is (or is not) scheduled, runs `steps` steps and returns the first
/// circle's `(position, velocity)`.
fn stepped(mut app: App, system: &str, scheduled: bool, steps: u64) -> (DVec2, DVec2) {
    assert_scheduled(&mut app, system, scheduled);
    step(&mut app, steps);
    first_state(&mut app)
}

#[test]
fn gravity_pulls_when_asked_and_is_absent_otherwise() {
    let app = one_circle("gravity: (0.0, -2.0)", "walls", "(0.0, 2.0)", "(0.0, 0.0)");
    let (p, v) = stepped(app, "apply_gravity", true, 60);
    // Semi-implicit Euler: v exact, x = x0 + g dt² n(n+1)/2 = 2 - 2·(1/60)²·1830.
    assert!((v.y + 2.0).abs() < 1e-5, "v = {v}");
    assert!(
        (p.y - (2.0 - 2.0 * 1830.0 / 3600.0)).abs() < 1e-4,
        "p = {p}"
    );

    let app = one_circle("", "walls", "(0.0, 2.0)", "(0.0, 0.0)");
    let state = stepped(app, "apply_gravity", false, 60);
    assert_eq!(state, (DVec2::new(0.0, 2.0), DVec2::ZERO));
}

#[test]
fn forces_act_under_every_solver_from_the_first_step() {
    for (solver, substeps) in [
        ("discrete", 1.0),
        ("substeps=4", 4.0),
        ("soft=1", 1.0),
        ("soft", 4.0),
        ("soft=8", 8.0),
        ("swept", 1.0),
        ("exact", 1.0),
    ] {
        // Gravity: semi-implicit Euler over n = 60·substeps steps of h = dt / substeps under
        // the discrete solvers; the exact parabola, x0 - g t²/2, under swept and exact, which
        // fly it themselves (no gravity system in their schedule).
        let (h, n) = (1.0 / (60.0 * substeps), 60.0 * substeps);
        let continuous = solver == "swept" || solver == "exact";
        let app = one_circle_under(
            solver,
            "gravity: (0.0, -2.0)",
            "walls",
            "(0.0, 2.0)",
            "(0.0, 0.0)",
        );
        let (p, v) = stepped(app, "apply_gravity", true, 60);
        assert!((v.y + 2.0).abs() < 1e-5, "{solver}: v = {v}");
        let expected = if continuous {
            2.0 - 0.5 * 2.0
        } else {
            2.0 - 2.0 * h * h * n * (n + 1.0) / 2.0
        };
        assert!((p.y - expected).abs() < 1e-4, "{solver}: p = {p}");
        let app = one_circle_under(solver, "drag: 0.5", "walls", "(-4.0, 0.0)", "(2.0, 0.0)");
        let (_, v) = stepped(app, "apply_drag", true, 120);
        assert_relative(
            &format!("{solver}: speed after 2 s of drag 0.5"),
            v.x,
            2.0 * (-1.0f64).exp(),
            1e-5,
        );
    }
}

#[test]
fn drag_slows_exponentially_when_asked_and_is_absent_otherwise() {
    let app = one_circle("drag: 0.5", "walls", "(-4.0, 0.0)", "(2.0, 0.0)");
    let (_, v) = stepped(app, "apply_drag", true, 120);
    assert_relative(
        "speed after 2 s of drag 0.5",
        v.x,
        2.0 * (-1.0f64).exp(),
        1e-5,
    );

    let app = one_circle("", "walls", "(-4.0, 0.0)", "(2.0, 0.0)");
    let (_, v) = stepped(app, "apply_drag", false, 120);
    assert_eq!(v, DVec2::new(2.0, 0.0));
}

#[test]
fn periodic_edges_wrap_and_walls_reflect() {
    let mut app = one_circle("", "periodic", "(4.8, 0.0)", "(3.0, 0.0)");
    assert_scheduled(&mut app, "wrap_around", true);
    assert_scheduled(&mut app, "bounce_off_walls", false);
    step(&mut app, 30);
    let (p, v) = first_state(&mut app);
    // 4.8 + 1.5 = 6.3 → wraps to -3.7, still moving right.
    assert!(
        (p.x + 3.7).abs() < 1e-4 && v == DVec2::new(3.0, 0.0),
        "p = {p}, v = {v}"
    );

    let mut app = one_circle("", "walls", "(4.0, 0.0)", "(3.0, 0.0)");
    assert_scheduled(&mut app, "wrap_around", false);
    assert_scheduled(&mut app, "bounce_off_walls", true);
    step(&mut app, 30);
    let (p, v) = first_state(&mut app);
    assert!(v.x < 0.0 && p.x <= 4.5, "p = {p}, v = {v}");
}

#[test]
fn periodic_circles_collide_across_the_seam() {
    let mut app = scene_app(
        "(arena: (size: (10.0, 10.0), boundary: periodic), mass: Equal(1.0),
          circles: [(position: (4.6, 0.0), velocity: (1.0, 0.0), radius: 0.3),
                    (position: (-4.6, 0.0), velocity: (-1.0, 0.0), radius: 0.3)])",
    );
    step(&mut app, 30);
    let cs = circles(&mut app);
    assert_eq!(pair_collisions(&app), 1);
    assert_eq!(
        (cs[0].1, cs[1].1),
        (DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0)),
        "they bounced off each other across the seam"
    );
}

#[test]
fn restitution_below_one_loses_the_right_energy() {
    let run = |e: f64| {
        let mut app = scene_app(&format!(
            "(mass: Equal(1.0), effects: (restitution: {e}),
              circles: [(position: (-2.0, 0.0), velocity: (2.0, 0.0), radius: 0.5),
                        (position: (2.0, 0.0), velocity: (-2.0, 0.0), radius: 0.5)])"
        ));
        step(&mut app, 90);
        let cs = circles(&mut app);
        cs[1].1.x - cs[0].1.x
    };
    // Separation speed is e times the approach speed (4).
    assert!((run(0.5) - 2.0).abs() < 1e-5);
    assert!((run(1.0) - 4.0).abs() < 1e-5);
}

#[test]
fn wall_restitution_scales_the_rebound() {
    let mut app = one_circle("wall_restitution: 0.5", "walls", "(4.0, 0.0)", "(3.0, 1.0)");
    step(&mut app, 30);
    assert_eq!(first_state(&mut app).1, DVec2::new(-1.5, 1.0));
}

#[test]
fn the_mass_model_decides_who_bounces() {
    let run = |mass: &str| {
        let mut app = scene_app(&format!(
            "(mass: {mass},
              circles: [(position: (-2.0, 0.0), velocity: (1.0, 0.0), radius: 1.0),
                        (position: (2.0, 0.0), velocity: (-1.0, 0.0), radius: 0.5)])"
        ));
        step(&mut app, 120);
        let cs = circles(&mut app);
        (cs[0].1.x, cs[1].1.x, cs[0].3, cs[1].3)
    };
    // Equal masses swap velocities.
    let (va, vb, ma, mb) = run("Equal(2.0)");
    assert_eq!((ma, mb), (2.0, 2.0));
    assert!(
        (va + 1.0).abs() < 1e-6 && (vb - 1.0).abs() < 1e-6,
        "{va} {vb}"
    );
    // Area masses (4:1): the big one keeps moving forward, slower; the small one flies back.
    let (va, vb, ma, mb) = run("Area(density: 1.0)");
    assert!((ma / mb - 4.0).abs() < 1e-5);
    assert!(
        (va - 0.2).abs() < 1e-5 && (vb - 2.2).abs() < 1e-5,
        "{va} {vb}"
    );
}
