//! Piles at rest under the contact solver: a column of 12 circles and a pyramid of 210 stand
//! for a minute without sinking or sliding, and a pile of 2000 mixed radii settles with its
//! contacts pressed in by no more than a fiftieth of the smaller radius.

mod common;

use std::path::Path;

use bevy::math::DVec2;
use bevy::prelude::*;
use common::*;
use moving_circles::circle::{CircleState, discs, snapshot};
use moving_circles::collide::overlaps::Overlaps;
use moving_circles::prelude::*;

fn scene(name: &str, solver: &str) -> App {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets/scenes")
        .join(name);
    let mut config = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
    config.solver = solver.parse().unwrap();
    create_app(config)
}

/// The deepest overlap among the circles now, in smaller radii.
fn overlap(app: &mut App) -> Overlaps {
    let arena = *app.world().resource::<Arena>();
    Overlaps::measure(&discs(&snapshot(app.world_mut())), &arena)
}

/// The topmost circle's centre.
fn top(circles: &[CircleState]) -> DVec2 {
    circles
        .iter()
        .map(|c| c.position)
        .max_by(|a, b| a.y.total_cmp(&b.y))
        .unwrap()
}

/// Runs `seconds` and returns the deepest overlap seen after any step once `settle` seconds
/// have passed, and how far the top circle moved from where it started.
fn stands(app: &mut App, seconds: f64, settle: f64) -> (f64, f64) {
    let start = top(&snapshot(app.world_mut()));
    let mut deepest = 0.0f64;
    for k in 0..(seconds * 60.0) as u64 {
        step(app, 1);
        if k as f64 >= settle * 60.0 {
            deepest = deepest.max(overlap(app).max);
        }
    }
    let moved = top(&snapshot(app.world_mut())).distance(start);
    (deepest, moved)
}

#[test]
fn a_column_of_twelve_stands_for_a_minute() {
    let mut app = scene("column.ron", "soft");
    let (deepest, moved) = stands(&mut app, 60.0, 1.0);
    // r = 0.5: the top may sink by the squeeze of eleven contacts, no more than 0.05 r.
    assert!(deepest <= 0.02, "pressed in by {deepest} radii");
    assert!(moved <= 0.05 * 0.5, "the top circle moved {moved}");
    let circles = snapshot(app.world_mut());
    assert!(
        circles.iter().all(|c| c.position.x == 0.0),
        "the column leaned"
    );
}

#[test]
fn a_pyramid_of_210_stands_for_a_minute() {
    let mut app = scene("pyramid.ron", "soft");
    let (deepest, moved) = stands(&mut app, 60.0, 1.0);
    assert!(deepest <= 0.02, "pressed in by {deepest} radii");
    assert!(moved <= 0.05 * 0.5, "the top circle moved {moved}");
}

#[test]
fn a_pile_of_2000_mixed_radii_settles_pressed_in_by_at_most_a_fiftieth() {
    let mut app = scene("pile.ron", "soft");
    step(&mut app, 15 * 60);
    let rest = overlap(&mut app);
    let circles = snapshot(app.world_mut());
    let kinetic: f64 = circles
        .iter()
        .map(|c| 0.5 * c.mass * c.velocity.length_squared())
        .sum();
    // N·m·g·r with the mean mass (density 1, r from 0.5 to 1) and radius.
    let (mean_mass, mean_radius) = (std::f64::consts::PI * 7.0 / 12.0, 0.75);
    let scale = 2000.0 * mean_mass * 9.81 * mean_radius;
    eprintln!(
        "pile at 15 s: overlap {:.4} max, {:.5} mean; kinetic energy {:.2e} N·m·g·r",
        rest.max,
        rest.mean(),
        kinetic / scale
    );
    assert!(rest.max <= 0.02, "pressed in by {} radii", rest.max);
    assert!(kinetic <= 1e-4 * scale, "still moving: {}", kinetic / scale);
    let escaped = app.world().resource::<CircleDiagnostics>().escaped;
    assert_eq!(escaped, 0);
}
