//! The four solvers keep their promises: `exact` conserves energy to 1e-9 over 100 s of a
//! 1000-circle gas and `swept` to 1e-6; fast circles do not tunnel under `swept` and `exact`
//! (and do under `discrete`); Newton's cradle comes out right under `exact`; the `exact`
//! engine persists across steps and takes in what user code changes; solvers can be switched
//! mid-run.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;
use moving_circles::solvers::exact::EngineState;

fn gas_1000(solver: Solver) -> App {
    create_app(gas_1000_config(solver))
}

fn gas_1000_config(solver: Solver) -> CirclesConfig {
    CirclesConfig {
        arena: Arena::centered(DVec2::new(10.4, 5.85)),
        spawn: SpawnConfig {
            area_fraction: Some(0.3),
            radius: (0.05, 0.1),
            speed: (0.5, 2.0),
            seed: 11,
            ..default()
        },
        solver,
        ..default()
    }
}

fn drift_over_100_seconds(solver: Solver) -> (f64, u64) {
    let mut app = gas_1000(solver);
    let n = circles(&mut app).len();
    assert!((950..=1050).contains(&n), "{n} circles");
    let (e0, _) = energy_momentum(&mut app);
    step(&mut app, 6000);
    let (e1, _) = energy_momentum(&mut app);
    assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
    assert_eq!(app.world().resource::<CircleDiagnostics>().escaped, 0);
    ((e1 - e0).abs() / e0, pair_collisions(&app))
}

#[test]
fn exact_conserves_energy_to_1e9_over_100_seconds_of_a_1000_circle_gas() {
    let (drift, collisions) = drift_over_100_seconds(Solver::Exact);
    assert!(
        collisions > 20_000,
        "tens of thousands of collisions expected, got {collisions}"
    );
    assert!(drift < 1e-9, "relative energy drift {drift:e}");
}

#[test]
fn swept_conserves_energy_to_1e6_over_100_seconds_of_a_1000_circle_gas() {
    let (drift, collisions) = drift_over_100_seconds(Solver::Swept);
    assert!(collisions > 20_000, "{collisions}");
    assert!(drift < 1e-6, "relative energy drift {drift:e}");
}

/// Two circles of radius 0.01 closing at 8 diameters per step (0.16 per step at 60 Hz).
fn fast_pair(solver: Solver) -> (u64, Vec<(DVec2, DVec2, f64, f64)>) {
    let mut app = create_app(CirclesConfig {
        solver,
        ..default()
    });
    spawn_head_on(&mut app, 1.0, 4.8, 0.01);
    step(&mut app, 20);
    (pair_collisions(&app), circles(&mut app))
}

#[test]
fn fast_circles_collide_under_swept_and_exact() {
    for solver in [Solver::Swept, Solver::Exact] {
        let (hits, cs) = fast_pair(solver);
        assert_eq!(hits, 1, "{solver}: the pair must collide once");
        assert!(
            cs[0].1.x < 0.0 && cs[1].1.x > 0.0,
            "{solver}: they bounce back: {cs:?}"
        );
        assert!(
            cs[0].0.x < cs[1].0.x,
            "{solver}: and never pass through each other"
        );
    }
}

#[test]
fn fast_circles_tunnel_under_discrete() {
    // What `discrete` does not promise: the closing speed skips over the contact.
    let (hits, cs) = fast_pair(Solver::Discrete);
    assert_eq!(hits, 0);
    assert!(
        cs[0].0.x > cs[1].0.x,
        "they passed through each other: {cs:?}"
    );
}

#[test]
fn newtons_cradle_sends_the_last_circle_off_at_the_strikers_speed_under_exact() {
    let mut app = create_app(
        Scene::load(std::path::Path::new("assets/scenes/cradle.ron"))
            .map(|c| CirclesConfig {
                solver: Solver::Exact,
                ..c
            })
            .unwrap(),
    );
    step(&mut app, 90);
    let cs = circles(&mut app);
    let striker_speed = 2.0;
    // Row circles are spawned first (indices 0..5 at x = 0..4), the striker last.
    for (i, c) in cs.iter().enumerate().take(4) {
        assert!(
            c.1.length() < 1e-12,
            "row circle {i} should be at rest, has {}",
            c.1
        );
    }
    assert!(
        cs[5].1.length() < 1e-12,
        "the striker should be at rest, has {}",
        cs[5].1
    );
    assert!(
        (cs[4].1 - DVec2::new(striker_speed, 0.0)).length() < 1e-12,
        "last circle: {}",
        cs[4].1
    );
}

#[test]
fn the_exact_engine_persists_across_steps() {
    let mut app = gas_1000(Solver::Exact);
    step(&mut app, 120);
    assert_eq!(
        app.world().resource::<EngineState>().rebuilds,
        1,
        "built once, then kept"
    );
    let mut app = gas_1000(Solver::Swept);
    step(&mut app, 120);
    assert_eq!(
        app.world().resource::<EngineState>().rebuilds,
        120,
        "swept starts afresh every step"
    );
}

/// The kept engine's rebuilds and updates so far.
fn engine_counts(app: &App) -> (u64, u64) {
    let engine = app.world().resource::<EngineState>();
    (engine.rebuilds, engine.updates)
}

#[test]
fn the_kept_exact_engine_takes_in_what_user_code_changes() {
    let mut app = gas_1000(Solver::Exact);
    step(&mut app, 2);
    let world = app.world_mut();
    let target = world
        .query_filtered::<Entity, With<Radius>>()
        .iter(world)
        .nth(7)
        .unwrap();
    let mut counts = engine_counts(&app);
    assert_eq!(counts, (1, 0));
    let mut change = |app: &mut App, edit: &dyn Fn(&mut EntityWorldMut), expected: (u64, u64)| {
        edit(&mut app.world_mut().entity_mut(target));
        step(app, 1);
        counts = (counts.0 + expected.0, counts.1 + expected.1);
        assert_eq!(engine_counts(app), counts);
    };

    // Written with the value it had: no change, the engine goes on untouched.
    change(
        &mut app,
        &|c| c.get_mut::<Position>().unwrap().set_changed(),
        (0, 0),
    );
    // A nudge that stops it, then a push: the engine updates that circle alone, and moves it
    // from where and as it was put.
    let dt = app
        .world()
        .resource::<Time<Fixed>>()
        .timestep()
        .as_secs_f64();
    let spot = state(&app, target).0 + DVec2::new(1e-3, 0.0);
    let stop = |c: &mut EntityWorldMut| {
        c.get_mut::<Position>().unwrap().0 = spot;
        c.get_mut::<Velocity>().unwrap().0 = DVec2::ZERO;
    };
    change(&mut app, &stop, (0, 1));
    assert_eq!(state(&app, target), (spot, DVec2::ZERO));
    let push = DVec2::new(0.0, 0.3);
    change(
        &mut app,
        &|c| c.get_mut::<Velocity>().unwrap().0 = push,
        (0, 1),
    );
    let (at, velocity) = state(&app, target);
    assert_eq!(velocity, push);
    assert!((at - (spot + push * dt)).length() < 1e-12, "{at}");
    // A new radius, mass or restitution, or a restitution taken away: a new engine.
    change(
        &mut app,
        &|c| c.get_mut::<Radius>().unwrap().0 *= 0.5,
        (1, 0),
    );
    change(&mut app, &|c| c.get_mut::<Mass>().unwrap().0 *= 2.0, (1, 0));
    change(
        &mut app,
        &|c| {
            c.insert(Restitution(0.5));
        },
        (1, 0),
    );
    change(
        &mut app,
        &|c| c.get_mut::<Restitution>().unwrap().0 = 0.25,
        (1, 0),
    );
    change(
        &mut app,
        &|c| {
            c.remove::<Restitution>();
        },
        (1, 0),
    );
    // And nothing changed: kept.
    change(&mut app, &|_| {}, (0, 0));

    // A component of the user's own moves a circle from the middle of the table to another
    // archetype, so a query yields the circles in another order than the engine knows: each
    // circle still gets its own state back, and the engine, in serial order, is kept.
    let before = entity_positions(&mut app);
    let tagged = before[3].0;
    app.world_mut().entity_mut(tagged).insert(Tag);
    let kept = engine_counts(&app);
    step(&mut app, 1);
    assert_eq!(engine_counts(&app), kept);
    let after = entity_positions(&mut app);
    for (entity, was) in before {
        let now = after.iter().find(|c| c.0 == entity).unwrap().1;
        // Speeds stay below 10 in this gas, so no circle moves 1/6 in a step of 1/60.
        assert!((now - was).length() < 1.0 / 6.0, "{entity}: {was} -> {now}");
    }
    change(&mut app, &|_| {}, (0, 0));
}

/// A component of the user's own.
#[derive(Component)]
struct Tag;

/// Every circle's entity and position, in query order.
fn entity_positions(app: &mut App) -> Vec<(Entity, DVec2)> {
    let world = app.world_mut();
    world
        .query::<(Entity, &Position)>()
        .iter(world)
        .map(|(e, p)| (e, p.0))
        .collect()
}

#[test]
fn solvers_can_be_switched_mid_run() {
    let mut app = gas_1000(Solver::Discrete);
    step(&mut app, 30);
    let (e0, _) = energy_momentum(&mut app);
    for solver in [
        Solver::Exact,
        Solver::Swept,
        Solver::Substeps(4),
        Solver::Exact,
    ] {
        *app.world_mut().resource_mut::<Solver>() = solver;
        step(&mut app, 30);
    }
    let (e1, _) = energy_momentum(&mut app);
    assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
    // Elastic impulses keep the energy to rounding under each of these, and a switch changes
    // nothing but the next step's method (measured: 7e-16).
    assert_relative("energy across solver switches", e1, e0, 1e-12);
    // `soft` then `soft=1` then back: the contact solver loses a little of a dense gas's energy
    // where several contacts meet in a step (measured -0.0044 and -0.0099 after 30 steps each),
    // and hands a state `exact` goes on from exactly.
    for (solver, most) in [
        (Solver::Soft(4), 0.01),
        (Solver::Soft(1), 0.02),
        (Solver::Exact, 0.02),
    ] {
        *app.world_mut().resource_mut::<Solver>() = solver;
        step(&mut app, 30);
        let (e, _) = energy_momentum(&mut app);
        assert_relative(&format!("energy after switching to {solver}"), e, e0, most);
        assert_eq!(app.world().resource::<CircleDiagnostics>().non_finite, 0);
    }
}

#[test]
fn an_event_budget_bounds_the_work_of_a_step() {
    for solver in [Solver::Exact, Solver::Swept] {
        // The default budget is never reached by this gas; with none, every step runs out of it
        // at its first event (a cell crossing, a hit) and processes no hit.
        let mut free = gas_1000(solver);
        step(&mut free, 10);
        assert_eq!(free.world().resource::<EngineState>().budget_exhausted, 0);
        assert_eq!(
            *free.world().resource::<EventBudget>(),
            EventBudget::default()
        );

        let mut bounded = gas_1000(solver);
        *bounded.world_mut().resource_mut::<EventBudget>() = EventBudget { swept: 0, exact: 0 };
        for k in 1..=10 {
            let hits = pair_collisions(&bounded) + wall_collisions(&bounded);
            step(&mut bounded, 1);
            let done = pair_collisions(&bounded) + wall_collisions(&bounded) - hits;
            assert_eq!(done, 0, "{solver:?}: hits in a step without budget");
            let exhausted = bounded.world().resource::<EngineState>().budget_exhausted;
            assert_eq!(exhausted, k, "{solver:?}: steps over budget");
        }
        assert_eq!(
            bounded.world().resource::<CircleDiagnostics>().non_finite,
            0
        );
    }
}

#[test]
fn a_step_a_stop_request_ends_is_not_kept_and_the_run_goes_on_from_where_it_stopped() {
    use moving_circles::step::schedule::{StepTotals, StopRequest};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    // `swept` hears the request while it gathers (the step moves nothing); `exact`, whose
    // engine is kept, after a few thousand of the step's events: it flies every circle to the
    // step's end without predicting again, so the engine must not be kept.
    for solver in [Solver::Swept, Solver::Exact] {
        // Steps of a second: tens of thousands of events each.
        let mut app = create_app(CirclesConfig {
            dt: 1.0,
            ..gas_1000_config(solver)
        });
        step(&mut app, 3);
        let stop = StopRequest(Arc::new(AtomicBool::new(true)));
        app.insert_resource(stop.clone());
        let (steps, cut, rebuilds) = {
            let world = app.world();
            let state = world.resource::<EngineState>();
            let totals = world.resource::<StepTotals>();
            (totals.steps, state.budget_exhausted, state.rebuilds)
        };
        step(&mut app, 1);
        stop.0.store(false, Ordering::Relaxed);
        let state = app.world().resource::<EngineState>();
        assert_eq!(
            state.budget_exhausted,
            cut + 1,
            "{solver}: the step was not cut short"
        );
        assert_eq!(app.world().resource::<StepTotals>().steps, steps + 1);
        if solver == Solver::Exact {
            assert_eq!(
                state.rebuilds, rebuilds,
                "{solver}: the stopped step rebuilt"
            );
        }
        assert_resumes_as_the_run_goes_on(&mut app, 3, &format!("{solver} after a stop"));
        let state = app.world().resource::<EngineState>();
        assert!(
            state.rebuilds > rebuilds,
            "{solver}: the step after the stop went on with an engine it had not predicted"
        );
    }
}

#[test]
fn a_step_whose_build_a_stop_gave_up_moves_turns_and_wakes_nothing() {
    use moving_circles::step::schedule::StopRequest;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    // Three circles at rest on the floor (asleep after the first step) and one spinning in the
    // air with a restitution of its own; a stop raised before a step that builds its engine
    // (`swept` always, `exact` once that circle lost its restitution) gives up the build:
    // nothing moves, not even the spin (once turned by the smooth circles' own rule), and the
    // count asleep stands.
    let scene = r#"(arena: (size: (4.0, 4.0)), effects: (gravity: (0.0, -9.81), restitution: 0.5),
        mass: Equal(1.0), circles: [
            (position: (-1.0, -1.75), radius: 0.25), (position: (0.0, -1.75), radius: 0.25),
            (position: (1.0, -1.75), radius: 0.25),
            (position: (0.0, 1.0), radius: 0.25, velocity: (1.0, 0.0), angular_velocity: 5.0),
        ])"#;
    for solver in [Solver::Swept, Solver::Exact] {
        let config = Scene::parse(scene, "stop.ron")
            .and_then(|s| s.to_config("stop.ron"))
            .unwrap();
        let mut app = create_app(CirclesConfig { solver, ..config });
        let world = app.world_mut();
        let mut spinning = world.query::<(Entity, &AngularVelocity)>();
        let (spinner, _) = spinning.iter(world).find(|(_, w)| w.0 != 0.0).unwrap();
        world.entity_mut(spinner).insert(Restitution(0.5));
        step(&mut app, 2);
        let state = |app: &mut App| {
            let world = app.world_mut();
            let asleep = world.resource::<Sleeping>().count;
            let mut circles = world.query::<(&Position, &Velocity, &Rotation)>();
            let circles: Vec<_> = circles
                .iter(world)
                .map(|(p, v, a)| (p.0, v.0, a.0))
                .collect();
            (circles, asleep)
        };
        let before = state(&mut app);
        assert_eq!(before.1, 3, "{solver}: the floor's circles sleep");
        app.world_mut().entity_mut(spinner).remove::<Restitution>();
        app.insert_resource(StopRequest(Arc::new(AtomicBool::new(true))));
        step(&mut app, 1);
        assert_eq!(
            state(&mut app),
            before,
            "{solver}: the given-up step changed the circles"
        );
    }
}

#[test]
fn a_stop_raised_during_the_last_step_is_reported_as_ending_the_run() {
    use moving_circles::step::schedule::StepTotals;
    use moving_circles::tools::run::{Progress, advance};
    use std::cell::Cell;
    // The stop comes while the run's last step runs (it may have cut it short): the run says
    // it was stopped, as the command line then reports it interrupted.
    let mut app = gas_1000(Solver::Exact);
    let mut progress = Progress::start(app.world_mut());
    let until = app.world().resource::<StepTotals>().steps + 1;
    let asked = Cell::new(0);
    let stop = || {
        asked.set(asked.get() + 1);
        asked.get() > 1
    };
    assert!(advance(&mut app, &mut progress, until, 1, stop, |_| {}));
    assert_eq!(app.world().resource::<StepTotals>().steps, until);
    // Never raised, the same run ends as completed.
    let until = until + 1;
    assert!(!advance(
        &mut app,
        &mut progress,
        until,
        1,
        || false,
        |_| {}
    ));
}
