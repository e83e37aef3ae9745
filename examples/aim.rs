//! Aiming with a ray cast: a turret at the left of the arena sweeps its aim upwards, and every
//! step casts a ray along it with `SpatialQuery`. A ray that meets a target (a static circle)
//! knocks it out; one that meets the shield (a segment wall in front of the top target) or an
//! arena wall does nothing. A circle cast then checks that a ball as wide as the gaps between
//! the targets' places would pass them, now that the row is gone.
//!
//! Headless, so it runs anywhere: `cargo run --example aim`. It exits with an error unless
//! exactly the four unshielded targets are knocked out.

use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// Where the turret stands, and the targets' column.
const TURRET: DVec2 = DVec2::new(-6.0, 0.0);
const TARGETS_X: f64 = 4.0;
/// The sweep: from 40° below the horizontal to 40° above, 1° per step.
const FIRST_DEGREES: f64 = -40.0;
const STEPS: u32 = 81;

#[derive(Component)]
struct Bullseye;

#[derive(Resource, Default)]
struct Score {
    knocked_out: u32,
    blocked: u32,
}

fn main() -> AppExit {
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(16.0, 12.0)),
        // The shield: a short wall across the line from the turret to the top target.
        segments: Segments(vec![Segment::new(
            DVec2::new(2.0, 2.4),
            DVec2::new(2.0, 4.0),
        )]),
        ..default()
    };
    let mut app = moving_circles::tools::run::headless_app(config);
    for k in -2..=2 {
        let at = DVec2::new(TARGETS_X, 2.0 * k as f64);
        app.world_mut()
            .spawn((Radius(0.3), Position(at), Mass::IMMOVABLE, Bullseye));
    }
    app.init_resource::<Score>().add_systems(Update, fire);
    for _ in 0..STEPS {
        app.update(); // one fixed step, then the turret fires once
    }
    let &Score {
        knocked_out,
        blocked,
    } = app.world().resource::<Score>();
    let left = app
        .world_mut()
        .query_filtered::<(), With<Bullseye>>()
        .iter(app.world())
        .count();
    println!(
        "knocked out {} targets, {} shots blocked by the shield, {left} target left",
        knocked_out, blocked
    );
    let clear = app
        .world_mut()
        .run_system_cached(passes_the_row)
        .expect("a system");
    if knocked_out == 4 && left == 1 && blocked > 0 && clear {
        AppExit::Success
    } else {
        eprintln!("aim: expected the four unshielded targets out and a clear way past the row");
        AppExit::error()
    }
}

/// One shot per step along the turret's current aim.
fn fire(
    totals: Res<StepTotals>,
    query: SpatialQuery,
    targets: Query<(), With<Bullseye>>,
    mut score: ResMut<Score>,
    mut commands: Commands,
) {
    let degrees = FIRST_DEGREES + totals.steps as f64 - 1.0;
    let aim = DVec2::from_angle(degrees.to_radians());
    let Some(hit) = query.ray_cast(TURRET, aim, f64::INFINITY, &QueryFilter::default()) else {
        return;
    };
    match hit.target {
        Target::Circle(e) if targets.contains(e) => {
            println!(
                "{degrees:+.0}°: hit the target at {:.2} after {:.2} m",
                hit.point, hit.distance
            );
            commands.entity(e).despawn();
            score.knocked_out += 1;
        }
        Target::Wall(Wall::Segment(_)) => score.blocked += 1,
        _ => {}
    }
}

/// Whether a ball of radius 0.9 rolled from the turret straight along the targets' bottom row
/// would now reach the right wall without touching a circle.
fn passes_the_row(query: SpatialQuery) -> bool {
    query.refresh(); // the targets were despawned since the last step
    let start = DVec2::new(TURRET.x, -4.0);
    let hit = query.circle_cast(start, 0.9, DVec2::X, f64::INFINITY, &QueryFilter::default());
    hit.is_some_and(|h| h.target == Target::Wall(Wall::Arena(ArenaWall::Right)))
}
