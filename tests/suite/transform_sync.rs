//! The core group's transform sync, headless, with frames shorter than the fixed step (a 144 Hz
//! display over the 60 Hz step): what a circle's `Transform` shows between two fixed steps, and
//! that a position written by game code is shown where it was put.

use std::time::Duration;

use bevy::math::DVec2;
use bevy::prelude::*;
use bevy::time::TimeUpdateStrategy;
use moving_circles::prelude::*;

/// Frames per second of the pretend display.
const DISPLAY_HZ: f64 = 144.0;

/// Every fixed step's end position of the followed circle, in order.
#[derive(Resource, Default)]
struct StepPositions(Vec<DVec2>);

/// The circle the tests follow.
#[derive(Component)]
struct Followed;

fn record_step(mut steps: ResMut<StepPositions>, circle: Single<&Position, With<Followed>>) {
    steps.0.push(circle.0);
}

/// A ball thrown in a walled box under gravity (so its path bends and bounces), with a
/// `Transform` as a game's own sprite would give it; `smoothing` on the circle if given.
fn app(smoothing: Option<Smoothing>) -> (App, Entity) {
    let config = CirclesConfig {
        effects: Effects {
            gravity: Some(DVec2::new(0.0, -9.81)),
            ..default()
        },
        solver: Solver::Substeps(4),
        ..default()
    };
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, CirclesPlugins::new(config)))
        .insert_resource(TimeUpdateStrategy::ManualDuration(Duration::from_secs_f64(
            1.0 / DISPLAY_HZ,
        )))
        .init_resource::<StepPositions>()
        .add_systems(FixedLast, record_step);
    let mut circle = app.world_mut().spawn((
        Followed,
        Radius(0.4),
        Position(DVec2::new(-5.0, 2.0)),
        Velocity(DVec2::new(6.0, 3.0)),
        Transform::from_xyz(0.0, 0.0, 3.0),
    ));
    if let Some(smoothing) = smoothing {
        circle.insert(smoothing);
    }
    let id = circle.id();
    (app, id)
}

fn shown(app: &App, id: Entity) -> Vec3 {
    app.world().get::<Transform>(id).unwrap().translation
}

/// The fraction of a step the fixed clock has left over after its last step.
fn overstep(app: &App) -> f64 {
    app.world()
        .resource::<Time<Fixed>>()
        .overstep_fraction_f64()
}

#[test]
fn an_interpolated_circle_is_shown_on_the_segment_between_its_last_two_steps() {
    let (mut app, id) = app(None);
    let mut frames_between = 0;
    for _ in 0..900 {
        app.update();
        let steps = &app.world().resource::<StepPositions>().0;
        let &[.., start, end] = steps.as_slice() else {
            continue;
        };
        let fraction = overstep(&app);
        let at = shown(&app, id);
        let expected = start.lerp(end, fraction).as_vec2();
        let tolerance = 1e-5 * (1.0 + expected.length());
        assert!(
            (at.truncate() - expected).length() <= tolerance,
            "shown {at} is not {fraction:.3} of the way from {start} to {end}"
        );
        assert_eq!(at.z, 3.0, "the game's depth is its own");
        if fraction > 0.2 && fraction < 0.8 && (end - start).length() > 0.01 {
            frames_between += 1;
        }
    }
    let steps = app.world().resource::<StepPositions>().0.len();
    assert!(steps > 300, "{steps} fixed steps in 900 frames at 144 Hz");
    assert!(
        frames_between > 300,
        "only {frames_between} frames fell between two steps"
    );
}

#[test]
fn extrapolated_and_unsmoothed_circles_are_shown_past_or_at_the_last_step() {
    for smoothing in [Smoothing::Extrapolate, Smoothing::Off] {
        let (mut app, id) = app(Some(smoothing));
        for _ in 0..200 {
            app.update();
            let Some(&end) = app.world().resource::<StepPositions>().0.last() else {
                continue;
            };
            let velocity = app.world().get::<Velocity>(id).unwrap().0;
            let dt = 1.0 / 60.0;
            let expected = match smoothing {
                Smoothing::Extrapolate => end + velocity * overstep(&app) * dt,
                _ => end,
            };
            let at = shown(&app, id).truncate();
            assert!(
                (at - expected.as_vec2()).length() <= 1e-5 * (1.0 + expected.length() as f32),
                "{smoothing:?}: shown {at}, expected {expected}"
            );
        }
    }
}

/// Moves the followed circle far away once and stops it, from `Update` as a game system would.
#[derive(Resource)]
struct TeleportAt(u32, DVec2);

fn teleport(
    mut at: ResMut<TeleportAt>,
    mut circle: Single<(&mut Position, &mut Velocity), With<Followed>>,
) {
    if at.0 == 0 {
        circle.0.0 = at.1;
        circle.1.0 = DVec2::ZERO;
    }
    at.0 = at.0.wrapping_sub(1);
}

#[test]
fn a_teleport_is_shown_where_it_was_put_and_never_smeared() {
    // Teleports in three frames in a row: at 144 Hz over 60 Hz steps the next frame runs a
    // step after some of them and none after others.
    let cases = [Smoothing::Interpolate, Smoothing::Extrapolate]
        .into_iter()
        .flat_map(|smoothing| [100, 101, 102].map(|frame| (smoothing, frame)));
    for (smoothing, frame) in cases {
        let (mut app, id) = app(Some(smoothing));
        let target = DVec2::new(6.0, -3.0);
        app.insert_resource(TeleportAt(frame, target))
            .add_systems(Update, teleport);
        for _ in 0..=frame {
            app.update();
        }
        let before = shown(&app, id).truncate().as_dvec2();
        assert!(
            (before - target).length() > 5.0,
            "the teleport is a long one"
        );
        // From here on every frame shows the circle near where it was put (it falls from
        // rest, 0.2 m in these 30 frames), never on the way from the old place.
        for after in 0..30 {
            app.update();
            let at = shown(&app, id).truncate().as_dvec2();
            assert!(
                (at - target).length() < 0.5,
                "{smoothing:?}, frame {after} after the teleport: shown at {at}, put at {target}"
            );
        }
    }
}

#[test]
fn a_teleport_from_the_fixed_step_just_before_the_step_is_not_smeared() {
    // A game system in `FixedUpdate` ordered only before the step (here also after the sleep
    // set, as late as it can be): the step's start must be taken after it, or the step would
    // be shown sliding from the old place.
    for smoothing in [Smoothing::Interpolate, Smoothing::Extrapolate] {
        for step in [40, 41, 42] {
            let (mut app, id) = app(Some(smoothing));
            let target = DVec2::new(6.0, -3.0);
            app.insert_resource(TeleportAt(step, target)).add_systems(
                FixedUpdate,
                teleport
                    .after(CircleSystems::Sleep)
                    .before(CircleSystems::Step),
            );
            let teleported = |app: &App| app.world().resource::<TeleportAt>().0 > step;
            let mut frame = 0;
            while !teleported(&app) {
                let before = shown(&app, id).truncate().as_dvec2();
                assert!((before - target).length() > 1.0, "not there before");
                app.update();
                frame += 1;
                assert!(frame < 200, "step {step} never came");
            }
            for after in 0..30 {
                let at = shown(&app, id).truncate().as_dvec2();
                assert!(
                    (at - target).length() < 0.5,
                    "{smoothing:?}, step {step}, frame {after} after the teleport: shown at \
                     {at}, put at {target}"
                );
                app.update();
            }
        }
    }
}

#[test]
fn circles_without_a_transform_are_left_alone() {
    let (mut app, _) = app(None);
    let bare = app
        .world_mut()
        .spawn((Radius(0.3), Position(DVec2::new(3.0, 0.0))))
        .id();
    for _ in 0..20 {
        app.update();
    }
    let world = app.world();
    assert!(world.get::<Transform>(bare).is_none());
    assert!(
        world
            .get::<moving_circles::game::transform_sync::StepEnds>(bare)
            .is_none()
    );
}
