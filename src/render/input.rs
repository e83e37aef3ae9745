//! Keyboard and mouse controls of the app: count, reset, pause, single step, speed, solver,
//! quit, and dragging a circle to fling it. Keys map to plain actions on resources and messages,
//! so the simulation itself knows nothing about input.

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::components::{Position, Radius, Velocity};
use crate::base::config::{Solver, SpawnConfig};
use crate::game::spawn::Respawn;

/// The app's keys and mouse drag.
#[derive(Clone, Copy, Debug, Default)]
pub struct InputPlugin;

impl Plugin for InputPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Drag>().add_systems(
            Update,
            (
                change_count,
                reset,
                pause_and_speed,
                single_step
                    .run_if(|keys: Res<ButtonInput<KeyCode>>| keys.just_pressed(KeyCode::Period)),
                switch_solver,
                quit,
                drag_and_fling,
            ),
        );
    }
}

/// Largest count `+` goes to: beyond this the app stops being interactive on a laptop.
pub const MAX_COUNT: usize = 1 << 20;
/// Slowest and fastest relative speed of simulated time.
const SPEED_RANGE: (f32, f32) = (1.0 / 64.0, 16.0);

fn change_count(
    keys: Res<ButtonInput<KeyCode>>,
    mut config: ResMut<SpawnConfig>,
    mut respawn: MessageWriter<Respawn>,
) {
    let more = keys.any_just_pressed([KeyCode::Equal, KeyCode::NumpadAdd]);
    let fewer = keys.any_just_pressed([KeyCode::Minus, KeyCode::NumpadSubtract]);
    let count = if more {
        (config.count * 2).clamp(1, MAX_COUNT)
    } else if fewer {
        (config.count / 2).max(1)
    } else {
        return;
    };
    if count != config.count {
        config.count = count;
        respawn.write(Respawn);
    }
}

fn reset(keys: Res<ButtonInput<KeyCode>>, mut respawn: MessageWriter<Respawn>) {
    if keys.just_pressed(KeyCode::KeyR) {
        respawn.write(Respawn);
    }
}

fn pause_and_speed(keys: Res<ButtonInput<KeyCode>>, mut time: ResMut<Time<Virtual>>) {
    if keys.just_pressed(KeyCode::Space) {
        if time.is_paused() {
            time.unpause();
        } else {
            time.pause();
        }
    }
    let factor = if keys.just_pressed(KeyCode::BracketRight) {
        2.0
    } else if keys.just_pressed(KeyCode::BracketLeft) {
        0.5
    } else {
        return;
    };
    let speed = (time.relative_speed() * factor).clamp(SPEED_RANGE.0, SPEED_RANGE.1);
    time.set_relative_speed(speed);
}

/// Advances exactly one fixed step while paused (the fixed clock does not tick then).
fn single_step(world: &mut World) {
    if world.resource::<Time<Virtual>>().is_paused() {
        world.run_schedule(FixedUpdate);
    }
}

fn switch_solver(keys: Res<ButtonInput<KeyCode>>, mut solver: ResMut<Solver>) {
    let digits = [
        KeyCode::Digit1,
        KeyCode::Digit2,
        KeyCode::Digit3,
        KeyCode::Digit4,
        KeyCode::Digit5,
    ];
    let chosen = digits
        .into_iter()
        .zip(Solver::APP_CHOICES)
        .find(|(key, _)| keys.just_pressed(*key));
    if let Some((_, new)) = chosen {
        *solver = new;
    }
}

fn quit(keys: Res<ButtonInput<KeyCode>>, mut exit: MessageWriter<AppExit>) {
    if keys.any_just_pressed([KeyCode::KeyQ, KeyCode::Escape]) {
        exit.write(AppExit::Success);
    }
}

/// The circle being dragged, where it was grabbed and how fast the pointer moves.
#[derive(Resource, Default, Debug)]
pub struct Drag {
    grabbed: Option<(Entity, DVec2)>,
    last_cursor: DVec2,
    velocity: DVec2,
}

/// Left button on a circle grabs it; moving the mouse carries it; releasing lets it go with the
/// pointer's recent velocity.
fn drag_and_fling(
    buttons: Res<ButtonInput<MouseButton>>,
    time: Res<Time<Real>>,
    window: Single<&Window>,
    camera: Single<(&Camera, &GlobalTransform)>,
    mut drag: ResMut<Drag>,
    mut circles: Query<(Entity, &mut Position, &mut Velocity, &Radius)>,
) {
    let (camera, camera_transform) = *camera;
    let Some(cursor) = window
        .cursor_position()
        .and_then(|p| camera.viewport_to_world_2d(camera_transform, p).ok())
        .map(Vec2::as_dvec2)
    else {
        return;
    };
    if buttons.just_pressed(MouseButton::Left) {
        let hit = circles
            .iter()
            .filter(|(_, p, _, r)| p.distance_squared(cursor) <= r.0 * r.0)
            .map(|(e, p, _, _)| (e, cursor - p.0))
            .last();
        *drag = Drag {
            grabbed: hit,
            last_cursor: cursor,
            velocity: DVec2::ZERO,
        };
    }
    let Some((entity, offset)) = drag.grabbed else {
        return;
    };
    let Ok((_, mut position, mut velocity, _)) = circles.get_mut(entity) else {
        drag.grabbed = None;
        return;
    };
    let dt = time.delta_secs_f64();
    if dt > 0.0 {
        // Smooth the pointer velocity over a few frames so a release fling is not one noisy sample.
        let sample = (cursor - drag.last_cursor) / dt;
        drag.velocity = drag.velocity.lerp(sample, 0.5);
    }
    drag.last_cursor = cursor;
    position.0 = cursor - offset;
    velocity.0 = drag.velocity;
    if buttons.just_released(MouseButton::Left) {
        drag.grabbed = None;
    }
}
