//! A kinematic paddle and a score kept from collision messages: a ball bounces under gravity
//! in a walled box; a paddle (an immovable circle, `Mass::IMMOVABLE`) that the game steers by
//! setting its `Velocity` every step follows the ball along the floor and sends it back up. The
//! score counts the ball's hits on the paddle (`CircleHit` messages), the misses its hits on
//! the floor (`WallHit` on `ArenaWall::Bottom`).
//!
//! Headless, so it runs anywhere: `cargo run --example paddle`. It exits with an error unless
//! the paddle scores at least 10 in 30 simulated seconds without a miss.

use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// The paddle's height and size, and the most speed the game gives it.
const PADDLE_Y: f64 = -3.6;
const PADDLE_RADIUS: f64 = 0.8;
const PADDLE_SPEED: f64 = 10.0;

#[derive(Component)]
struct Ball;

#[derive(Component)]
struct Paddle;

#[derive(Resource, Default)]
struct Score {
    hits: u32,
    misses: u32,
}

fn main() -> AppExit {
    let config = CirclesConfig {
        effects: Effects {
            gravity: Some(DVec2::new(0.0, -9.81)),
            hit_messages: true,
            ..default()
        },
        solver: Solver::Soft(4),
        ..default()
    };
    let mut app = moving_circles::tools::run::headless_app(config);
    app.init_resource::<Score>()
        .add_systems(FixedUpdate, steer.before(CircleSystems::Step))
        .add_systems(FixedUpdate, keep_score.after(CircleSystems::Step));
    app.world_mut().spawn((
        Ball,
        Radius(0.3),
        Position(DVec2::new(3.0, 2.0)),
        Velocity(DVec2::new(-2.5, 0.0)),
    ));
    app.world_mut().spawn((
        Paddle,
        Radius(PADDLE_RADIUS),
        Position(DVec2::new(0.0, PADDLE_Y)),
        Mass::IMMOVABLE,
    ));
    for _ in 0..30 * 60 {
        app.update(); // one fixed step: 30 simulated seconds in all
    }
    let score = app.world().resource::<Score>();
    println!("score {}, misses {}", score.hits, score.misses);
    if score.hits >= 10 && score.misses == 0 {
        AppExit::Success
    } else {
        eprintln!("paddle: the paddle did not keep the ball up");
        AppExit::error()
    }
}

/// The paddle, and not the ball.
type PaddleOnly = (With<Paddle>, Without<Ball>);

/// Before each step: the paddle heads for where the ball will come down to its height (a
/// little to the outside of it, so the ball bounces back towards the middle), no faster than
/// its speed, and stays at its height.
fn steer(
    ball: Single<(&Position, &Velocity), With<Ball>>,
    mut paddle: Single<(&Position, &mut Velocity), PaddleOnly>,
) {
    let ((p, v), (at, velocity)) = (*ball, &mut *paddle);
    // y(t) = p.y + v.y t − g t² / 2 reaches the top of the paddle at the later root.
    let (g, drop) = (9.81, p.y - (PADDLE_Y + PADDLE_RADIUS));
    let t = (v.y + (v.y * v.y + 2.0 * g * drop.max(0.0)).sqrt()) / g;
    let landing = (p.x + v.x * t).clamp(-7.0, 7.0);
    let target = landing + 0.25 * landing.signum();
    let gap = target - at.x;
    velocity.0 = DVec2::new((8.0 * gap).clamp(-PADDLE_SPEED, PADDLE_SPEED), 0.0);
}

/// After each step: a hit between the ball and the paddle scores, a hit on the floor misses.
fn keep_score(
    mut hits: MessageReader<CircleHit>,
    mut walls: MessageReader<WallHit>,
    ball: Single<Entity, With<Ball>>,
    mut score: ResMut<Score>,
) {
    score.hits += hits.read().filter(|h| h.a == *ball || h.b == *ball).count() as u32;
    let floor = Wall::Arena(ArenaWall::Bottom);
    score.misses += walls.read().filter(|h| h.wall == floor).count() as u32;
}
