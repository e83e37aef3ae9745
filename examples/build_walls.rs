//! Walls built while the game runs: an open arena (no edges) under gravity, a ball falling,
//! and a system of the game's that lays a floor of segment walls under it half a second in.
//! The next step already has the segment system (the group reconciles its effects whenever
//! the segment walls change), and the ball lands on the new floor instead of falling for good.
//!
//! Headless, so it runs anywhere: `cargo run --example build_walls`. It exits with an error
//! if the ball is not resting on the floor after five simulated seconds.

use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// Where the floor goes, and how high the ball starts.
const FLOOR_Y: f64 = -3.0;
const START_Y: f64 = 3.0;
const RADIUS: f64 = 0.4;

fn main() -> AppExit {
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(16.0, 9.0)).with_boundary(Boundary::Open),
        effects: Effects {
            gravity: Some(DVec2::new(0.0, -9.81)),
            wall_restitution: 0.3,
            ..default()
        },
        solver: Solver::Soft(4),
        ..default()
    };
    let mut app = moving_circles::tools::run::headless_app(config);
    app.world_mut().spawn((
        Radius(RADIUS),
        Position(DVec2::new(0.0, START_Y)),
        Velocity(DVec2::ZERO),
    ));
    app.add_systems(Update, lay_the_floor);
    for _ in 0..300 {
        app.update(); // one fixed step: five simulated seconds in all
    }
    let y = app
        .world_mut()
        .query::<&Position>()
        .single(app.world())
        .expect("one ball")
        .0
        .y;
    let rest = FLOOR_Y + RADIUS;
    println!("after 5 s the ball is at y = {y:.4}; resting on the floor puts it at {rest}");
    if (y - rest).abs() < 0.05 * RADIUS {
        AppExit::Success
    } else {
        eprintln!("build_walls: the ball is not on the floor built under it");
        AppExit::error()
    }
}

/// Half a simulated second in, puts a floor of three segment walls under the ball.
fn lay_the_floor(totals: Res<StepTotals>, mut segments: ResMut<Segments>) {
    if totals.steps != 30 || !segments.is_empty() {
        return;
    }
    let points = [-6.0, -2.0, 2.0, 6.0].map(|x| DVec2::new(x, FLOOR_Y));
    segments.0 = points
        .windows(2)
        .map(|pair| Segment::new(pair[0], pair[1]))
        .collect();
    println!(
        "t = 0.5 s: floor of {} segment walls built",
        segments.0.len()
    );
}
