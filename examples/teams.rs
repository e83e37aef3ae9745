//! Two teams on collision layers: red circles meet red ones and blue meet blue, so each team
//! bounces around as a gas of its own while the two fly through each other. A wall of static
//! circles across the middle is in group 0 (the default), which both teams meet; its gap is
//! filled by a plug in the blue group alone, which stops blue and lets red through.
//!
//! Headless, so it runs anywhere: `cargo run --example teams`. It exits with an error unless
//! both teams collided within themselves, no collision message paired a red with a blue circle
//! or red with the plug, and red circles got through the gap while the plug stopped every blue
//! one.

use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// The groups: plain circles (the wall) are in group 0.
const RED: u32 = 1 << 1;
const BLUE: u32 = 1 << 2;

#[derive(Component, Clone, Copy, PartialEq, Eq, Debug)]
enum Team {
    Red,
    Blue,
    Plug,
}

/// Collisions by kind of pair.
#[derive(Resource, Default, Debug)]
struct Hits {
    within_a_team: u32,
    blue_on_the_plug: u32,
    /// Red on blue, or red on the plug: pairs that must never meet.
    across: u32,
}

fn main() -> AppExit {
    let mut app = moving_circles::tools::run::headless_app(CirclesConfig {
        arena: Arena::centered(DVec2::new(16.0, 9.0)),
        effects: Effects {
            hit_messages: true,
            ..default()
        },
        solver: Solver::Exact,
        ..default()
    });
    app.init_resource::<Hits>()
        .add_systems(FixedUpdate, count_hits.after(CircleSystems::Step));
    // The wall: static circles at x = 0, with a gap from y = -1 to 1 that the plug fills.
    for k in -9..=9 {
        let y = 0.5 * k as f64;
        if y.abs() > 1.0 {
            app.world_mut()
                .spawn((Radius(0.25), Position(DVec2::new(0.0, y)), Mass::IMMOVABLE));
        }
    }
    // The plug is in the blue group alone and meets only blue: red passes it.
    app.world_mut().spawn((
        Team::Plug,
        Radius(1.0),
        Position(DVec2::ZERO),
        Mass::IMMOVABLE,
        CollisionLayers::new(BLUE, BLUE),
    ));
    // Each team meets itself and group 0 (the wall), not the other team.
    for (team, group, x) in [(Team::Red, RED, -6.0), (Team::Blue, BLUE, -4.0)] {
        for i in 0..30 {
            let (col, row) = ((i % 5) as f64, (i / 5) as f64);
            let angle = 0.7 * i as f64 + if team == Team::Red { 0.0 } else { 0.35 };
            app.world_mut().spawn((
                team,
                Radius(0.2),
                Position(DVec2::new(x + 0.5 * col, -3.0 + row)),
                Velocity(3.0 * DVec2::from_angle(angle)),
                CollisionLayers::new(group, group | 1),
            ));
        }
    }
    for _ in 0..30 * 60 {
        app.update(); // one fixed step: 30 simulated seconds in all
    }
    let through = |team: Team, app: &mut App| {
        app.world_mut()
            .query::<(&Team, &Position)>()
            .iter(app.world())
            .filter(|&(t, p)| *t == team && p.0.x > 0.0)
            .count()
    };
    let (red, blue) = (through(Team::Red, &mut app), through(Team::Blue, &mut app));
    let hits = app.world().resource::<Hits>();
    println!(
        "{} hits within a team, {} of blue on the plug, {} across; \
         {red} red and {blue} blue past the wall",
        hits.within_a_team, hits.blue_on_the_plug, hits.across
    );
    let stopped = hits.blue_on_the_plug > 0 && blue == 0;
    if hits.within_a_team > 100 && hits.across == 0 && red > 0 && stopped {
        AppExit::Success
    } else {
        eprintln!("teams: the layers let the wrong circles meet or pass");
        AppExit::error()
    }
}

/// Sorts each collision by the teams of its pair (the wall has no team).
fn count_hits(mut messages: MessageReader<CircleHit>, teams: Query<&Team>, mut hits: ResMut<Hits>) {
    for hit in messages.read() {
        match (teams.get(hit.a), teams.get(hit.b)) {
            (Ok(a), Ok(b)) if a == b => hits.within_a_team += 1,
            (Ok(Team::Blue), Ok(Team::Plug)) | (Ok(Team::Plug), Ok(Team::Blue)) => {
                hits.blue_on_the_plug += 1;
            }
            (Ok(_), Ok(_)) => hits.across += 1,
            _ => {} // a circle and the wall
        }
    }
}
