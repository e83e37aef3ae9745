//! The rollback examples' game: a pile of circles in a box with friction and gravity, a few of
//! their own restitution and a few that do not turn, a drop falling on it every 1.5 s, and, from
//! 4 s on, two players whose inputs now and then kick the circle nearest their spot. Its step runs in
//! GGRS's frames (`GgrsCirclesPlugin`); one app update is one GGRS frame.

use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use bevy_ggrs::prelude::*;
use bevy_ggrs::{LocalInputs, LocalPlayers, RollbackFrameCount};
use moving_circles::base::components::CircleSerial;
use moving_circles::game::rollback::ggrs::{GgrsCirclesPlugin, GgrsCirclesSystems};
use moving_circles::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// GGRS's configuration: an input is a byte, 0 for none, 1 to 8 a kick in one of eight
/// directions.
pub type PileConfig = GgrsConfig<u8>;

/// GGRS frames a second, and fixed steps a second.
pub const FPS: usize = 60;

/// Players.
pub const PLAYERS: usize = 2;

/// The game under `solver`, with no session yet. Each `update` runs one GGRS frame.
pub fn pile_app(solver: Solver) -> App {
    let config = CirclesConfig {
        arena: Arena::centered(DVec2::new(6.0, 8.0)).with_boundary(Boundary::Walls),
        spawn: SpawnConfig {
            count: 50,
            radius: (0.15, 0.3),
            speed: (0.0, 1.0),
            seed: 5,
            ..default()
        },
        effects: Effects {
            collisions: true,
            gravity: Some(DVec2::new(0.0, -9.81)),
            restitution: 0.3,
            wall_restitution: 0.3,
            friction: 0.4,
            ..default()
        },
        drop: Some(DropConfig {
            count: 5,
            every: 1.5,
            position: DVec2::new(0.0, 3.5),
            spread: 1.0,
            radius: 0.2,
            velocity: DVec2::new(0.0, -4.0),
            seed: 2,
        }),
        solver,
        dt: 1.0 / FPS as f64,
        ..default()
    };
    let mut app = App::new();
    app.add_plugins(MinimalPlugins)
        .add_plugins(CirclesPlugins::new(config))
        .add_plugins((GgrsPlugin::<PileConfig>::default(), GgrsCirclesPlugin))
        .insert_resource(RollbackFrameRate(FPS))
        // One GGRS frame's time per update, however long the update takes.
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_nanos(
            1_000_000_000 / FPS as u64,
        )))
        .add_systems(PostStartup, give_parts)
        .add_systems(ReadInputs, read_inputs)
        .add_systems(GgrsSchedule, kick.before(GgrsCirclesSystems::Step));
    app
}

/// Every fourth circle its own restitution; every ninth from the third one does not turn.
fn give_parts(mut commands: Commands, circles: Query<(Entity, &CircleSerial)>) {
    let mut circles: Vec<_> = circles.iter().map(|(e, s)| (*s, e)).collect();
    circles.sort_unstable();
    for (k, &(_, e)) in circles.iter().enumerate() {
        if k % 4 == 0 {
            commands.entity(e).insert(Restitution(0.8));
        }
        if k % 9 == 2 {
            commands.entity(e).remove::<(AngularVelocity, Rotation)>();
        }
    }
}

/// Each local player's input of this frame: from 4 s on (when the pile has come to rest), a
/// kick one frame in sixty, in a direction drawn from the frame and the player (the same on
/// every machine, so a run can be replayed).
fn read_inputs(mut commands: Commands, players: Res<LocalPlayers>, frame: Res<RollbackFrameCount>) {
    let mut inputs = bevy::platform::collections::HashMap::default();
    for &handle in &players.0 {
        inputs.insert(handle, input_of(frame.0, handle));
    }
    commands.insert_resource(LocalInputs::<PileConfig>(inputs));
}

/// Player `handle`'s input at `frame`.
pub fn input_of(frame: i32, handle: usize) -> u8 {
    let mut rng = ChaCha8Rng::seed_from_u64(frame as u64);
    rng.set_stream(handle as u64);
    if frame >= 4 * FPS as i32 && rng.random_ratio(1, 60) {
        rng.random_range(1..=8)
    } else {
        0
    }
}

/// Kicks, for each player whose input says so, the circle nearest its spot (the left or the
/// right of the floor) by 5 m/s in the input's direction.
pub fn kick(
    inputs: Res<PlayerInputs<PileConfig>>,
    mut circles: Query<(&Position, &CircleSerial, &mut Velocity)>,
) {
    for (handle, &(input, _)) in inputs.iter().enumerate() {
        if input == 0 {
            continue;
        }
        let spot = DVec2::new(if handle == 0 { -1.5 } else { 1.5 }, -3.5);
        let nearest = circles
            .iter()
            .map(|(p, s, _)| ((p.0 - spot).length_squared(), *s))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let Some((_, serial)) = nearest else {
            continue;
        };
        let angle = f64::from(input - 1) * std::f64::consts::FRAC_PI_4;
        for (_, s, mut v) in &mut circles {
            if *s == serial {
                v.0 += 5.0 * DVec2::from_angle(angle);
            }
        }
    }
}
