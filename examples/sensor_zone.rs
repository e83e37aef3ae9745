//! A sensor zone: a goal circle in the middle of a walled box that the balls fly through (a
//! `Sensor` pushes nothing) and that counts them as they come and go, from `OverlapStarted`
//! and `OverlapEnded` messages; its `SensorOverlaps` lists who is inside now. A second, picky
//! zone on its own layer sees only the gold balls.
//!
//! Headless, so it runs anywhere: `cargo run --example sensor_zone`. It exits with an error
//! unless the zones counted at least 20 entries, every ball's entries and exits add up to
//! where it is now, the picky zone saw only gold balls, and the balls' energy is unchanged
//! (elastic walls and hits: the zones took and gave nothing).

use bevy::math::DVec2;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// The gold balls' group; every other ball is in group 0 (the default).
const GOLD: u32 = 1 << 1;

#[derive(Component)]
struct Gold;

/// Entries minus exits, per zone and ball; and all entries.
#[derive(Resource, Default)]
struct Tally {
    inside: HashMap<(Entity, Entity), i32>,
    entries: u32,
}

fn main() -> AppExit {
    let mut app = moving_circles::tools::run::headless_app(CirclesConfig {
        spawn: SpawnConfig {
            count: 40,
            radius: (0.15, 0.3),
            ..default()
        },
        ..default()
    });
    app.init_resource::<Tally>()
        .add_systems(FixedUpdate, tally.after(CircleSystems::Sensors));
    let goal = app
        .world_mut()
        .spawn((Radius(1.5), Position(DVec2::ZERO), Mass::IMMOVABLE, Sensor))
        .id();
    // The picky zone is in the gold group and meets only it.
    let picky = app
        .world_mut()
        .spawn((
            Radius(1.0),
            Position(DVec2::new(5.0, 2.0)),
            Mass::IMMOVABLE,
            Sensor,
            CollisionLayers::new(GOLD, GOLD),
        ))
        .id();
    // Every fourth ball spawned above is gold: in group 0 (so it still hits the others) and
    // in the gold group.
    let balls: Vec<Entity> = app
        .world_mut()
        .query_filtered::<Entity, Without<Sensor>>()
        .iter(app.world())
        .collect();
    for &ball in balls.iter().step_by(4) {
        app.world_mut()
            .entity_mut(ball)
            .insert((Gold, CollisionLayers::new(1 | GOLD, u32::MAX)));
    }
    let energy = |app: &mut App| -> f64 {
        app.world_mut()
            .query_filtered::<(&Velocity, &Mass), Without<Sensor>>()
            .iter(app.world())
            .map(|(v, m)| 0.5 * m.0 * v.0.length_squared())
            .sum()
    };
    let before = energy(&mut app);
    for _ in 0..20 * 60 {
        app.update(); // one fixed step: 20 simulated seconds in all
    }
    let after = energy(&mut app);
    let tally = app.world().resource::<Tally>();
    let mut ok = tally.entries >= 20 && ((after - before) / before).abs() < 1e-9;
    for (&(zone, ball), &count) in &tally.inside {
        let now = app.world().get::<SensorOverlaps>(zone).unwrap();
        ok &= count == i32::from(now.contains(ball));
        ok &= zone != picky || app.world().get::<Gold>(ball).is_some();
    }
    let inside = app
        .world()
        .get::<SensorOverlaps>(goal)
        .unwrap()
        .circles()
        .len();
    println!(
        "{} entries; {inside} balls in the goal now; energy {before:.6} -> {after:.6}",
        tally.entries
    );
    if ok {
        AppExit::Success
    } else {
        eprintln!("sensor_zone: the zones' counts do not add up, or they pushed a ball");
        AppExit::error()
    }
}

/// Counts every ball that came into or left a zone this step.
fn tally(
    mut started: MessageReader<OverlapStarted>,
    mut ended: MessageReader<OverlapEnded>,
    mut tally: ResMut<Tally>,
) {
    for m in started.read() {
        *tally.inside.entry((m.sensor, m.circle)).or_default() += 1;
        tally.entries += 1;
    }
    for m in ended.read() {
        *tally.inside.entry((m.sensor, m.circle)).or_default() -= 1;
    }
}
