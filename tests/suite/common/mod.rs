//! Shared helpers for the headless system tests: a `MinimalPlugins` app stepped one fixed step
//! per `update()`, and assertion helpers that say what was expected.
#![allow(dead_code)] // each test file uses its own subset

pub mod binary;

use std::hash::{DefaultHasher, Hash, Hasher};

use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// Every solver, as the tests that promise something under every solver run them: the course's
/// method alone and at 4 substeps, the contact solver at 4 (`soft`) and 8 substeps, and the two
/// event-driven solvers. `soft=1` and `soft=2` are not among them yet: they break the hard
/// cases' bounds (`soft=1`: a tangent path deflected by 0.067, the jammed packing overlapping by
/// 0.46 radii, measured 2026-12-06; `soft=2`: deflected by 0.044, overlapping by 0.19, the
/// touching pair's energy off by 0.49 where 0.4 is allowed, the 45-degree corner shot leaving
/// at 3 - 4e-16 where the bound is exact, measured 2026-12-07), which the contact solver's
/// issue carries.
pub const SOLVERS: [Solver; 6] = [
    Solver::Discrete,
    Solver::Substeps(4),
    Solver::Soft(4),
    Solver::Soft(8),
    Solver::Swept,
    Solver::Exact,
];

/// Whether `solver` (a solver's name) is the contact solver, at any substeps.
pub fn is_soft(solver: &str) -> bool {
    solver == "soft" || solver.starts_with("soft=")
}

/// Whether `solver` (a solver's name) is event-driven.
pub fn is_continuous(solver: &str) -> bool {
    solver == "swept" || solver == "exact"
}

/// A headless app running `config`, already past `Startup` (circles spawned), in which every
/// `update()` advances exactly one fixed step: the same app `moving_circles run` steps.
pub fn create_app(config: CirclesConfig) -> App {
    moving_circles::tools::run::headless_app(config)
}

/// A unit box asked for `fraction` of circles of radii `radius` at speed 1, placed by
/// `placement`, run by `exact` at dt 0.01.
pub fn dense_config(
    fraction: f64,
    radius: (f64, f64),
    boundary: Boundary,
    placement: Placement,
) -> CirclesConfig {
    CirclesConfig {
        arena: Arena::unit_square(boundary),
        spawn: SpawnConfig {
            area_fraction: Some(fraction),
            radius,
            speed: (1.0, 1.0),
            placement,
            ..SpawnConfig::default()
        },
        solver: Solver::Exact,
        dt: 0.01,
        ..CirclesConfig::default()
    }
}

/// The fraction of `arena` the `circles` cover.
pub fn area_fraction(circles: &[CircleState], arena: &Arena) -> f64 {
    arena.area_fraction(circles.iter().map(|c| c.radius))
}

/// Runs `n` fixed steps and checks the app really advanced that many.
pub fn step(app: &mut App, n: u64) {
    let before = app.world().resource::<StepTotals>().steps;
    for _ in 0..n {
        app.update();
    }
    let after = app.world().resource::<StepTotals>().steps;
    assert_eq!(
        after - before,
        n,
        "expected {n} fixed steps, the app ran {}",
        after - before
    );
}

/// Circle-circle collisions since the last (re)spawn.
pub fn pair_collisions(app: &App) -> u64 {
    app.world().resource::<PairCollisions>().count
}

/// Wall hits since the last (re)spawn.
pub fn wall_collisions(app: &App) -> u64 {
    app.world().resource::<WallCollisions>().count
}

/// Spawns one circle.
pub fn spawn_circle(
    app: &mut App,
    position: DVec2,
    velocity: DVec2,
    radius: f64,
    mass: f64,
) -> Entity {
    app.world_mut()
        .spawn((
            Radius(radius),
            Position(position),
            Velocity(velocity),
            Mass(mass),
        ))
        .id()
}

/// Two equal unit-mass circles on the x axis at `∓x`, each moving towards the other at `speed`.
pub fn spawn_head_on(app: &mut App, x: f64, speed: f64, radius: f64) -> (Entity, Entity) {
    (
        spawn_circle(
            app,
            DVec2::new(-x, 0.0),
            DVec2::new(speed, 0.0),
            radius,
            1.0,
        ),
        spawn_circle(
            app,
            DVec2::new(x, 0.0),
            DVec2::new(-speed, 0.0),
            radius,
            1.0,
        ),
    )
}

/// Asserts that a circle at `p` of radius `r` lies entirely inside `arena`.
pub fn assert_inside(arena: &Arena, p: DVec2, r: f64, what: &str) {
    assert!(
        p.x - r >= arena.min.x
            && p.x + r <= arena.max.x
            && p.y - r >= arena.min.y
            && p.y + r <= arena.max.y,
        "{what} at {p} with radius {r} is not inside {arena:?}"
    );
}

/// Circles for the unit box from random `(x, y, vx, vy, r, m)` tuples, keeping each that lies
/// inside (with walls) and clear of the ones kept before it (by the minimum image when
/// periodic); and the box.
pub fn unit_box_gas(
    seeds: &[(f64, f64, f64, f64, f64, f64)],
    periodic: bool,
) -> (Vec<CircleState>, Arena) {
    let arena = Arena::unit_square(if periodic {
        Boundary::Periodic
    } else {
        Boundary::Walls
    });
    let mut circles: Vec<CircleState> = Vec::new();
    for &(x, y, vx, vy, r, m) in seeds {
        let p = DVec2::new(x, y);
        let clear = circles
            .iter()
            .all(|c| arena.offset(c.position, p).length() > c.radius + r);
        let inside = periodic || (r..=1.0 - r).contains(&x) && (r..=1.0 - r).contains(&y);
        if clear && inside {
            circles.push(CircleState::new(p, DVec2::new(vx, vy), r).with_mass(m));
        }
    }
    (circles, arena)
}

/// `(position, velocity)` of a circle.
pub fn state(app: &App, entity: Entity) -> (DVec2, DVec2) {
    let e = app.world().entity(entity);
    (
        e.get::<Position>().unwrap().0,
        e.get::<Velocity>().unwrap().0,
    )
}

/// Every circle as `(position, velocity, radius, mass)`, in query order.
pub fn circles(app: &mut App) -> Vec<(DVec2, DVec2, f64, f64)> {
    app.world_mut()
        .query::<(&Position, &Velocity, &Radius, &Mass)>()
        .iter(app.world())
        .map(|(p, v, r, m)| (p.0, v.0, r.0, m.0))
        .collect()
}

/// A hash of the exact bits of every position and velocity.
pub fn state_hash(app: &mut App) -> u64 {
    let mut hasher = DefaultHasher::new();
    for (p, v, r, m) in circles(app) {
        for x in [p.x, p.y, v.x, v.y, r, m] {
            x.to_bits().hash(&mut hasher);
        }
    }
    hasher.finish()
}

/// The exact bits of each circle's motion, spin and angle, in the order given.
pub fn state_bits(circles: &[CircleState]) -> Vec<[u64; 6]> {
    circles
        .iter()
        .map(|c| {
            let (p, v) = (c.position, c.velocity);
            [p.x, p.y, v.x, v.y, c.angular_velocity, c.rotation].map(f64::to_bits)
        })
        .collect()
}

/// Kinetic energy and momentum, summed in f64.
pub fn energy_momentum(app: &mut App) -> (f64, DVec2) {
    circles(app)
        .iter()
        .fold((0.0, DVec2::ZERO), |(e, p), &(_, v, _, m)| {
            let (v, m) = (v, m);
            (e + 0.5 * m * v.length_squared(), p + m * v)
        })
}

/// Asserts `|actual - expected| <= tolerance · max(|expected|, 1e-12)`, saying what differed.
pub fn assert_relative(what: &str, actual: f64, expected: f64, tolerance: f64) {
    let error = (actual - expected).abs() / expected.abs().max(1e-12);
    assert!(
        error <= tolerance,
        "{what}: expected {expected}, got {actual} (relative error {error:e} > {tolerance:e})"
    );
}

/// A headless app for a scene given as RON text (checked like a scene file).
pub fn scene_app(ron: &str) -> App {
    let config = Scene::parse(ron, "test scene")
        .and_then(|s| s.to_config("test scene"))
        .unwrap_or_else(|e| panic!("test scene does not load: {e}"));
    create_app(config)
}

/// Short names of the systems in the simulation's schedules.
pub fn system_names(app: &mut App) -> Vec<String> {
    moving_circles::step::schedule::scheduled_systems(app)
        .into_iter()
        .map(|(_, s)| s.rsplit("::").next().unwrap().to_owned())
        .collect()
}

/// Asserts that the schedule does (or does not) hold a system of this name.
pub fn assert_scheduled(app: &mut App, system: &str, expected: bool) {
    let names = system_names(app);
    assert_eq!(
        names.iter().any(|n| n == system),
        expected,
        "expected `{system}` {} the schedule; it holds {names:?}",
        if expected { "in" } else { "absent from" }
    );
}

/// Something a test does (a change, a write), with what it is called in its messages.
pub type Named<F> = (&'static str, F);

/// Takes a checkpoint of `app` as it is now, reads it back with our own reader and resumes it,
/// then runs both `steps` more: they must end at the same circles, bit for bit. `what` names
/// the case in the messages.
pub fn assert_resumes_as_the_run_goes_on(app: &mut App, steps: u64, what: &str) {
    assert_resumes_through(app, |_| {}, steps, what);
}

/// [`assert_resumes_as_the_run_goes_on`], with `then` done to the run and to the resumed one
/// right after the checkpoint (a kick from user code, say).
pub fn assert_resumes_through(app: &mut App, then: impl Fn(&mut App), steps: u64, what: &str) {
    use moving_circles::base::circle::snapshot;
    use moving_circles::tools::checkpoint::Checkpoint;
    use moving_circles::tools::run::Progress;
    let progress = Progress::start(app.world_mut());
    let bytes = Checkpoint::take(app.world_mut(), what, &progress).to_bytes();
    let (mut resumed, _) = Checkpoint::from_bytes(&bytes, "test.checkpoint")
        .and_then(|c| c.resume("test.checkpoint"))
        .unwrap_or_else(|e| panic!("{what}: our own checkpoint: {e}"));
    then(app);
    then(&mut resumed);
    step(app, steps);
    step(&mut resumed, steps);
    let (ran, went_on) = (snapshot(app.world_mut()), snapshot(resumed.world_mut()));
    assert_eq!(ran, went_on, "{what}: the resumed run goes elsewhere");
    // Where each circle stands in coming to rest too (what the next checkpoint keeps).
    let rest = |app: &mut App| -> Vec<Sleep> {
        let mut sleep = app.world_mut().query_filtered::<&Sleep, With<Radius>>();
        sleep.iter(app.world()).copied().collect()
    };
    assert_eq!(
        rest(app),
        rest(&mut resumed),
        "{what}: the resumed run rests otherwise"
    );
}
