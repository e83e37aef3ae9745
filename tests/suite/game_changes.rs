//! Settings changed by a game's own system while the simulation runs take effect at the next
//! step, under every solver: the effects (gravity on and off), the arena (walls to periodic),
//! the segment walls (one put in a circle's path) and the solver (a fast pair that only the
//! continuous solvers catch). A checkpoint taken right after such a change, before the step
//! that applies it, resumes as the run goes on.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::step::effects::EffectRegistry;

/// What the game's system does, and in which frame.
#[derive(Resource)]
struct Change {
    frame: u32,
    apply: fn(&mut World),
    seen: u32,
}

/// A game system in `Update`: applies the change in its frame.
fn change(world: &mut World) {
    let mut change = world.resource_mut::<Change>();
    change.seen += 1;
    if change.seen == change.frame {
        let apply = change.apply;
        apply(world);
    }
}

/// A headless app under `solver` with one circle, whose settings `apply` changes in `frame`.
fn app(solver: Solver, circle: (DVec2, DVec2), frame: u32, apply: fn(&mut World)) -> App {
    let mut app = create_app(CirclesConfig {
        solver,
        ..default()
    });
    spawn_circle(&mut app, circle.0, circle.1, 0.4, 1.0);
    app.insert_resource(Change {
        frame,
        apply,
        seen: 0,
    })
    .add_systems(Update, change);
    app
}

fn only_circle(app: &mut App) -> (DVec2, DVec2) {
    let all = circles(app);
    assert_eq!(all.len(), 1);
    (all[0].0, all[0].1)
}

fn scheduled(app: &App, effect: Effect) -> bool {
    app.world()
        .resource::<EffectRegistry>()
        .is_scheduled(effect)
}

#[test]
fn gravity_switched_on_and_off_by_a_system_pulls_and_stops_pulling() {
    for solver in SOLVERS {
        let mut app = app(solver, (DVec2::ZERO, DVec2::ZERO), 3, |world| {
            world.resource_mut::<Effects>().gravity = Some(DVec2::new(0.0, -9.81));
        });
        step(&mut app, 33);
        let (at, v) = only_circle(&mut app);
        assert!(scheduled(&app, Effect::Gravity), "{solver}");
        assert!(
            at.y < -0.3 && v.y < -4.0,
            "{solver}: half a second of gravity left it at {at}, moving {v}"
        );
        app.world_mut().resource_mut::<Effects>().gravity = None;
        step(&mut app, 1);
        let (_, before) = only_circle(&mut app);
        step(&mut app, 5);
        let (_, after) = only_circle(&mut app);
        assert!(!scheduled(&app, Effect::Gravity), "{solver}");
        assert_eq!(before, after, "{solver}: no gravity, no change of speed");
    }
}

#[test]
fn an_arena_made_periodic_by_a_system_lets_a_circle_out_the_other_side() {
    for solver in SOLVERS {
        let circle = (DVec2::new(7.0, 0.0), DVec2::new(3.0, 0.0));
        let mut app = app(solver, circle, 2, |world| {
            world.resource_mut::<Arena>().boundary = Boundary::Periodic;
        });
        step(&mut app, 60);
        let (at, v) = only_circle(&mut app);
        assert!(scheduled(&app, Effect::Periodic) && !scheduled(&app, Effect::Walls));
        assert!(
            at.x < -4.0 && v.x > 0.0,
            "{solver}: the circle should have crossed the right edge to the left side: at {at}, moving {v}"
        );
    }
}

#[test]
fn a_segment_wall_put_up_by_a_system_stops_a_circle() {
    for solver in SOLVERS {
        let circle = (DVec2::new(-3.0, 0.0), DVec2::new(3.0, 0.0));
        let mut app = app(solver, circle, 2, |world| {
            let wall = Segment::new(DVec2::new(0.0, -2.0), DVec2::new(0.0, 2.0));
            *world.resource_mut::<Segments>() = Segments(vec![wall]);
        });
        step(&mut app, 90);
        let (at, v) = only_circle(&mut app);
        assert!(scheduled(&app, Effect::Segments), "{solver}");
        assert!(
            at.x < -0.4 && v.x < 0.0,
            "{solver}: the circle should have bounced off the new wall: at {at}, moving {v}"
        );
    }
}

#[test]
fn a_solver_switched_by_a_system_steps_from_then_on() {
    // Two small circles closing at 0.16 a step: a discrete step never sees them touch.
    let fast = |app: &mut App| spawn_head_on(app, 1.0, 4.8, 0.01);
    for from in SOLVERS {
        for to in [Solver::Exact, Solver::Discrete] {
            let mut app = create_app(CirclesConfig {
                solver: from,
                ..default()
            });
            fast(&mut app);
            app.insert_resource(Change {
                frame: 2,
                apply: if to == Solver::Exact {
                    |world| *world.resource_mut::<Solver>() = Solver::Exact
                } else {
                    |world| *world.resource_mut::<Solver>() = Solver::Discrete
                },
                seen: 0,
            })
            .add_systems(Update, change);
            step(&mut app, 20);
            let hits = app.world().resource::<PairCollisions>().count;
            let expected = u64::from(to == Solver::Exact);
            assert_eq!(hits, expected, "{from} switched to {to} after one step");
        }
    }
}

#[test]
fn a_checkpoint_taken_right_after_a_games_changes_resumes_as_the_run_goes_on() {
    // What a game may do between two steps: steer a few circles (`exact` updates its kept
    // engine), steer them all (it builds afresh), switch gravity on. A checkpoint of the state
    // then must be read back by our own reader and go on as the run does; under `exact` its
    // engine must agree with its circles (it refused them all before).
    let changes: [Named<fn(&mut World)>; 3] = [
        ("one steered", |world| {
            let mut velocities = world.query::<&mut Velocity>();
            velocities
                .iter_mut(world)
                .step_by(8)
                .for_each(|mut v| v.0 = -v.0);
        }),
        ("all steered", |world| {
            let mut velocities = world.query::<&mut Velocity>();
            velocities.iter_mut(world).for_each(|mut v| v.0 *= 0.5);
        }),
        ("gravity on", |world| {
            world.resource_mut::<Effects>().gravity = Some(DVec2::new(0.0, -9.81));
        }),
    ];
    for solver in SOLVERS {
        for (what, apply) in changes {
            let mut app = create_app(CirclesConfig {
                solver,
                spawn: SpawnConfig {
                    count: 40,
                    ..default()
                },
                ..default()
            });
            step(&mut app, 20);
            apply(app.world_mut());
            assert_resumes_as_the_run_goes_on(&mut app, 30, &format!("{solver}, {what}"));
        }
    }
}
