//! Sleeping under the time-stepped solvers: a heap at rest falls asleep and stays exactly where
//! it is, a ball dropped onto it wakes it and it sleeps again (a fast one in the step it
//! arrives, under every `soft=N`, `substeps=4`, `swept` and `exact`), your code's writes wake a
//! sleeping circle, a change of the effects wakes them all, and nothing sleeps without gravity
//! (a circle a checkpoint marks asleep is awake under `exact` and `swept` without it).

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::circle::{CircleState, snapshot, snapshot_with_entities};
use moving_circles::prelude::*;

/// The time-stepped solvers that hold a heap at rest. `discrete`'s single contact pass does
/// not: its heap keeps boiling (circles wander a third of a radius in half a second), so it
/// never sleeps as a whole; a lone circle at rest sleeps under it all the same.
const TIME_STEPPED: [&str; 2] = ["soft", "substeps=4"];

/// Twenty balls of radius 0.25 dropped at rest into a narrow box under gravity.
fn heap(solver: &str) -> App {
    heap_with(solver, "")
}

/// [`heap`] with more `effects` (fields of the scene's `effects`, each followed by a comma).
fn heap_with(solver: &str, effects: &str) -> App {
    let scene = format!(
        "(solver: \"{solver}\", arena: (size: (3.0, 8.0)),
          effects: ({effects} gravity: (0.0, -9.81), restitution: 0.3, wall_restitution: 0.3),
          mass: Equal(1.0),
          spawn: (count: 20, radius: (0.25, 0.25), speed: (0.0, 0.0), seed: 4))"
    );
    let config = Scene::parse(&scene, "heap.ron")
        .and_then(|s| s.to_config("heap.ron"))
        .unwrap();
    create_app(config)
}

fn asleep(app: &mut App) -> Vec<bool> {
    app.world_mut()
        .query::<&Sleep>()
        .iter(app.world())
        .map(|s| s.asleep)
        .collect()
}

fn positions(circles: &[CircleState]) -> Vec<DVec2> {
    circles.iter().map(|c| c.position).collect()
}

/// Steps until every circle sleeps (at most `seconds`), and returns the seconds it took.
fn until_asleep(app: &mut App, seconds: f64) -> Option<f64> {
    for k in 1..=(seconds * 60.0) as u64 {
        step(app, 1);
        if asleep(app).iter().all(|&s| s) {
            return Some(k as f64 / 60.0);
        }
    }
    None
}

#[test]
fn a_heap_falls_asleep_and_stays_exactly_where_it_is_under_every_time_stepped_solver() {
    for solver in TIME_STEPPED {
        let mut app = heap(solver);
        let took = until_asleep(&mut app, 20.0);
        eprintln!("{solver}: asleep after {took:?} s");
        assert!(took.is_some(), "{solver}: the heap never fell asleep");
        assert_eq!(app.world().resource::<Sleeping>().count, 20, "{solver}");
        let before = snapshot(app.world_mut());
        assert!(before.iter().all(|c| c.velocity == DVec2::ZERO), "{solver}");
        step(&mut app, 600);
        let after = snapshot(app.world_mut());
        assert_eq!(
            positions(&before),
            positions(&after),
            "{solver}: a sleeper moved"
        );
        assert!(
            asleep(&mut app).iter().all(|&s| s),
            "{solver}: woke by itself"
        );
    }
}

#[test]
fn a_ball_at_rest_on_the_floor_sleeps_under_discrete_too() {
    let config = Scene::parse(
        "(solver: \"discrete\", arena: (size: (3.0, 8.0)),
          effects: (gravity: (0.0, -9.81), restitution: 0.3, wall_restitution: 0.3),
          circles: [(position: (0.3, 0.0), radius: 0.25)])",
        "ball.ron",
    )
    .and_then(|s| s.to_config("ball.ron"))
    .unwrap();
    let mut app = create_app(config);
    let took = until_asleep(&mut app, 10.0).expect("the ball never slept");
    let p = snapshot(app.world_mut())[0].position;
    assert!(
        took < 5.0 && (p.y + 3.75).abs() < 0.1,
        "after {took} s at {p}"
    );
    step(&mut app, 300);
    assert_eq!(snapshot(app.world_mut())[0].position, p, "a sleeper moved");
}

#[test]
fn a_ball_dropped_on_a_sleeping_heap_wakes_it_and_it_sleeps_again() {
    for solver in TIME_STEPPED {
        let mut app = heap(solver);
        until_asleep(&mut app, 20.0).expect("asleep");
        let ball = app
            .world_mut()
            .spawn((Radius(0.25), Position(DVec2::new(0.1, 3.5)), Mass(1.0)))
            .id();
        let mut woke = false;
        for _ in 0..120 {
            step(&mut app, 1);
            woke |= asleep(&mut app).iter().filter(|&&s| !s).count() > 1;
        }
        assert!(woke, "{solver}: the hit woke nothing");
        assert!(
            until_asleep(&mut app, 20.0).is_some(),
            "{solver}: never slept again"
        );
        let p = app.world().get::<Position>(ball).unwrap().0;
        assert!(p.y < 3.0, "{solver}: the ball did not land: {p}");
    }
}

#[test]
fn a_ball_that_reaches_a_sleeping_heap_within_one_step_wakes_it_in_that_step() {
    // At 60 m/s the ball covers a metre a step: it starts 0.6 above the heap (far outside
    // touching) and meets it before the step ends. The heap must wake before that step, so
    // that the hit moves it, not bounce the ball off circles held as immovable.
    for solver in ["soft", "soft=1", "soft=8", "substeps=4", "swept", "exact"] {
        let mut app = heap(solver);
        until_asleep(&mut app, 20.0).expect("asleep");
        let top = snapshot(app.world_mut())
            .iter()
            .map(|c| c.position.y + c.radius)
            .fold(f64::NEG_INFINITY, f64::max);
        let x = snapshot(app.world_mut())
            .iter()
            .max_by(|a, b| a.position.y.total_cmp(&b.position.y))
            .unwrap()
            .position
            .x;
        let ball = app
            .world_mut()
            .spawn((
                Radius(0.25),
                Position(DVec2::new(x, top + 0.25 + 0.6)),
                Velocity(DVec2::new(0.0, -60.0)),
                Mass(1.0),
            ))
            .id();
        step(&mut app, 1);
        let heap_moving = snapshot_with_entities(app.world_mut())
            .iter()
            .filter(|(e, c)| *e != ball && c.velocity != DVec2::ZERO)
            .count();
        let awake = asleep(&mut app).iter().filter(|&&s| !s).count();
        assert!(
            awake > 1 && heap_moving > 0,
            "{solver}: {awake} awake, {heap_moving} of the heap moving after the hit"
        );
    }
}

#[test]
fn writing_a_sleeping_circles_velocity_wakes_it_and_it_moves() {
    for solver in TIME_STEPPED {
        let mut app = heap(solver);
        until_asleep(&mut app, 20.0).expect("asleep");
        let (entity, before) = app
            .world_mut()
            .query::<(Entity, &Position)>()
            .iter(app.world())
            .map(|(e, p)| (e, p.0))
            .max_by(|a, b| a.1.y.total_cmp(&b.1.y))
            .unwrap();
        app.world_mut().get_mut::<Velocity>(entity).unwrap().0 = DVec2::new(0.0, 3.0);
        step(&mut app, 1);
        let sleep = *app.world().get::<Sleep>(entity).unwrap();
        let after = app.world().get::<Position>(entity).unwrap().0;
        assert!(!sleep.asleep, "{solver}: still asleep");
        assert!(after.y > before.y, "{solver}: {before} -> {after}");
    }
}

#[test]
fn a_change_of_the_effects_wakes_every_circle() {
    let mut app = heap("soft");
    until_asleep(&mut app, 20.0).expect("asleep");
    app.world_mut().resource_mut::<Effects>().gravity = Some(DVec2::new(-9.81, 0.0));
    step(&mut app, 1);
    assert!(
        asleep(&mut app).iter().all(|&s| !s),
        "gravity turned sideways, yet circles sleep"
    );
    assert_eq!(app.world().resource::<Sleeping>().count, 0);
}

#[test]
fn nothing_sleeps_without_gravity_and_sleeping_can_be_switched_off() {
    // A gas slowed to a crawl by drag rests nowhere: no sleep system is even scheduled.
    let config = Scene::parse(
        "(effects: (drag: 5.0), solver: \"soft\", spawn: (count: 30, speed: (0.0, 0.2)))",
        "drag.ron",
    )
    .and_then(|s| s.to_config("drag.ron"))
    .unwrap();
    let mut app = create_app(config);
    step(&mut app, 300);
    assert!(asleep(&mut app).iter().all(|&s| !s));
    let registry = app
        .world()
        .resource::<moving_circles::step::effects::EffectRegistry>();
    assert!(!registry.is_scheduled(Effect::Sleep));
    // The heap with sleeping off: never asleep.
    let mut app = heap("soft");
    app.world_mut().resource_mut::<Effects>().sleep.enabled = false;
    assert!(until_asleep(&mut app, 5.0).is_none());
}

#[test]
fn a_checkpoint_marking_a_circle_asleep_resumes_under_exact_without_gravity_to_a_readable_one() {
    use moving_circles::base::components::Sleep;
    use moving_circles::tools::checkpoint::Checkpoint;
    use moving_circles::tools::run::Progress;
    // A circle at rest marked asleep in a checkpoint of an `exact` run without gravity (where
    // nothing rests) and one flying at it. The engine flies it like any circle: once hit it
    // moved on still marked asleep, and the checkpoint of where the run ended was refused by
    // our own reader ("asleep but moves"). Reviewing the rule that refuses that found this.
    for solver in [Solver::Exact, Solver::Swept] {
        let config = CirclesConfig {
            arena: Arena::centered(DVec2::new(4.0, 2.0)),
            solver,
            spawn: SpawnConfig {
                count: 0,
                ..default()
            },
            ..default()
        };
        let mut app = create_app(config);
        let still = spawn_circle(&mut app, DVec2::new(1.0, 0.0), DVec2::ZERO, 0.2, 1.0);
        spawn_circle(
            &mut app,
            DVec2::new(-1.0, 0.0),
            DVec2::new(2.0, 0.0),
            0.2,
            1.0,
        );
        app.world_mut().entity_mut(still).insert(Sleep {
            asleep: true,
            ..default()
        });
        let progress = Progress::start(app.world_mut());
        let bytes = Checkpoint::take(app.world_mut(), "asleep", &progress).to_bytes();
        let (mut resumed, progress) = Checkpoint::from_bytes(&bytes, "asleep.checkpoint")
            .and_then(|c| c.resume("asleep.checkpoint"))
            .unwrap();
        step(&mut resumed, 60); // the hit comes at 0.8 s
        let world = resumed.world_mut();
        let moving = world
            .query::<(&Velocity, &Sleep)>()
            .iter(world)
            .filter(|(v, _)| v.0 != DVec2::ZERO)
            .count();
        assert_eq!(moving, 1, "{solver}: the hit passes the motion on");
        assert!(world.query::<&Sleep>().iter(world).all(|s| !s.asleep));
        let end = Checkpoint::take(world, "asleep", &progress).to_bytes();
        if let Err(error) = Checkpoint::from_bytes(&end, "end.checkpoint") {
            panic!("{solver}: our own checkpoint is refused: {error}");
        }
    }
}

#[test]
fn a_heap_checkpointed_while_still_goes_on_as_the_run_does_under_the_event_driven_solvers() {
    // Half a second after the whole heap fell asleep nothing has moved for 30 steps, and
    // `swept` keeps its engine. A checkpoint taken then must lead to the same heap and the same
    // sleepers' timers, left alone and after the same kick to the run and the resumed one.
    for solver in ["swept", "exact"] {
        let mut app = heap_with(solver, "");
        until_asleep(&mut app, 20.0).expect("asleep");
        step(&mut app, 30);
        assert_resumes_as_the_run_goes_on(&mut app, 30, &format!("{solver}, still"));
        let kick = |app: &mut App| {
            let mut circles = app.world_mut().query::<(&Position, &mut Velocity)>();
            let mut top = circles
                .iter_mut(app.world_mut())
                .max_by(|a, b| a.0.0.y.total_cmp(&b.0.0.y))
                .unwrap();
            top.1.0 = DVec2::new(1.5, 2.0);
        };
        assert_resumes_through(&mut app, kick, 120, solver);
    }
}

#[test]
fn a_checkpoint_taken_after_your_code_wakes_a_sleeping_circle_resumes_as_the_run_goes_on() {
    // A game sets a sleeping circle moving (or turning) and takes a checkpoint before the next
    // step, which is the one that would wake it. Our reader refuses a circle asleep that moves
    // or turns, so the checkpoint must say it is awake, as the next step makes it.
    let writes: [Named<fn(&mut EntityWorldMut)>; 2] = [
        ("moving", |circle| {
            circle.get_mut::<Velocity>().unwrap().0 = DVec2::new(0.5, 3.0)
        }),
        ("turning", |circle| {
            circle.get_mut::<AngularVelocity>().unwrap().0 = 2.0
        }),
    ];
    // With drag too, which leaves sleepers at rest alone but drags the one set moving.
    let solvers = ["soft", "substeps=4", "swept", "exact"];
    for (solver, effects) in solvers
        .into_iter()
        .flat_map(|s| [(s, ""), (s, "drag: 0.5,")])
    {
        for (what, write) in writes {
            let mut app = heap_with(solver, effects);
            until_asleep(&mut app, 20.0).expect("asleep");
            let top = app
                .world_mut()
                .query::<(Entity, &Position)>()
                .iter(app.world())
                .max_by(|a, b| a.1.0.y.total_cmp(&b.1.0.y))
                .map(|(e, _)| e)
                .unwrap();
            write(&mut app.world_mut().entity_mut(top));
            let dragged = if effects.is_empty() { "" } else { " with drag" };
            let case = format!("{solver}, {what}{dragged}");
            assert_resumes_as_the_run_goes_on(&mut app, 30, &case);
        }
    }
}
