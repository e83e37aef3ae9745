//! Layers and sensors under every solver, against brute force: no solver resolves, predicts or
//! reports a hit between circles whose layers do not meet; teams that do not meet move exactly
//! as they would alone; a sensor pushes nothing and reports exactly the circles overlapping it,
//! step by step; layers changed by game code take effect at the next step, also in a kept
//! `exact` engine; spatial queries filter by membership and leave sensors out on request.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::arena::{Arena, Boundary};
use moving_circles::checkpoint::Checkpoint;
use moving_circles::circle::CircleState;
use moving_circles::exact::engine::EventEngine;
use moving_circles::prelude::*;
use moving_circles::run::Progress;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A circle's memberships and filters, written out: a circle without layers is in group 0 and
/// meets every group.
fn masks(layers: Option<CollisionLayers>) -> (u32, u32) {
    layers.map_or((1, u32::MAX), |l| (l.memberships, l.filters))
}

/// Whether two circles meet, written out from the definition: neither is a sensor, and each is
/// in a group the other meets.
fn brute_meets(a: (Option<CollisionLayers>, bool), b: (Option<CollisionLayers>, bool)) -> bool {
    let ((ma, fa), (mb, fb)) = (masks(a.0), masks(b.0));
    !a.1 && !b.1 && (ma & fb) != 0 && (mb & fa) != 0
}

/// An app with `solver` in a 10 × 10 walled box with nothing spawned, hits reported.
fn empty_box(solver: Solver) -> App {
    create_app(CirclesConfig {
        arena: Arena::centered(DVec2::splat(10.0)),
        solver,
        spawn: SpawnConfig {
            count: 0,
            ..default()
        },
        effects: Effects {
            hit_messages: true,
            ..default()
        },
        ..default()
    })
}

/// One circle of a test scene: centre, velocity, radius, layers, sensor.
type Body = (DVec2, DVec2, f64, Option<CollisionLayers>, bool);

/// `n` circles on a jittered grid (no two overlap), with random velocities; `layers(i)` gives
/// circle `i`'s layers and whether it is a sensor.
fn grid_bodies(
    rng: &mut ChaCha8Rng,
    n: usize,
    offset: DVec2,
    layers: impl Fn(usize, &mut ChaCha8Rng) -> (Option<CollisionLayers>, bool),
) -> Vec<Body> {
    (0..n)
        .map(|i| {
            let cell = DVec2::new((i % 8) as f64, (i / 8) as f64) * 1.1 - DVec2::splat(4.0);
            let jitter = DVec2::new(rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1));
            let v = DVec2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            let r = rng.random_range(0.2..0.4);
            let (l, sensor) = layers(i, rng);
            (cell + offset + jitter, v, r, l, sensor)
        })
        .collect()
}

fn spawn_bodies(app: &mut App, bodies: &[Body]) -> Vec<Entity> {
    bodies
        .iter()
        .map(|&(p, v, r, layers, sensor)| {
            let mut e = app.world_mut().spawn((Radius(r), Position(p), Velocity(v)));
            if let Some(l) = layers {
                e.insert(l);
            }
            if sensor {
                e.insert(Sensor);
            }
            e.id()
        })
        .collect()
}

fn states(app: &App, entities: &[Entity]) -> Vec<(DVec2, DVec2)> {
    entities.iter().map(|&e| state(app, e)).collect()
}

#[test]
fn teams_that_do_not_meet_move_exactly_as_they_would_alone() {
    let red = CollisionLayers::new(0b01, 0b01);
    let blue = CollisionLayers::new(0b10, 0b10);
    for solver in EVERY_SOLVER {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let reds = grid_bodies(&mut rng, 40, DVec2::ZERO, |_, _| (Some(red), false));
        let blues = grid_bodies(&mut rng, 40, DVec2::new(0.45, 0.3), |_, _| {
            (Some(blue), false)
        });
        let mut both = empty_box(solver);
        // Interleaved, so the teams share cells, archetypes and the solvers' arrays.
        let mut red_ids = Vec::new();
        let mut blue_ids = Vec::new();
        for (r, b) in reds.iter().zip(&blues) {
            red_ids.extend(spawn_bodies(&mut both, std::slice::from_ref(r)));
            blue_ids.extend(spawn_bodies(&mut both, std::slice::from_ref(b)));
        }
        let mut alone_red = empty_box(solver);
        let alone_red_ids = spawn_bodies(&mut alone_red, &reds);
        let mut alone_blue = empty_box(solver);
        let alone_blue_ids = spawn_bodies(&mut alone_blue, &blues);
        for app in [&mut both, &mut alone_red, &mut alone_blue] {
            step(app, 120);
        }
        let together = pair_collisions(&both);
        let apart = pair_collisions(&alone_red) + pair_collisions(&alone_blue);
        assert!(apart > 50, "{solver}: too few collisions to test ({apart})");
        assert_eq!(together, apart, "{solver}: pair collisions");
        assert_eq!(
            states(&both, &red_ids),
            states(&alone_red, &alone_red_ids),
            "{solver}: red"
        );
        assert_eq!(
            states(&both, &blue_ids),
            states(&alone_blue, &alone_blue_ids),
            "{solver}: blue"
        );
    }
}

/// Every circle's layers and sensor flag, by entity.
fn kinds(app: &mut App) -> bevy::ecs::entity::EntityHashMap<(Option<CollisionLayers>, bool)> {
    app.world_mut()
        .query::<(Entity, Option<&CollisionLayers>, Has<Sensor>)>()
        .iter(app.world())
        .map(|(e, l, s)| (e, (l.copied(), s)))
        .collect()
}

/// Random layers over three groups, one circle in six a sensor, one in four without layers.
fn random_kind(rng: &mut ChaCha8Rng) -> (Option<CollisionLayers>, bool) {
    let layers = rng
        .random_bool(0.75)
        .then(|| CollisionLayers::new(1 << rng.random_range(0..3), rng.random_range(1..8)));
    (layers, rng.random_bool(1.0 / 6.0))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Random layers and sensors: every hit any solver reports is between circles that meet,
    /// by the definition written out; the continuous solvers leave no meeting pair overlapping
    /// (so no pair that meets was dropped), while pairs that do not meet overlap freely.
    #[test]
    fn no_solver_pairs_circles_that_do_not_meet(seed in any::<u64>()) {
        for solver in EVERY_SOLVER {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut a = grid_bodies(&mut rng, 40, DVec2::ZERO, |_, rng| random_kind(rng));
            // A second set over the first: pairs that do not meet start overlapping.
            let b = grid_bodies(&mut rng, 40, DVec2::new(0.45, 0.3), |_, rng| {
                let (l, sensor) = random_kind(rng);
                // Each circle of the second set must not meet one of the first it may overlap.
                (Some(l.unwrap_or(CollisionLayers::new(0b1000, 0b1000))), sensor)
            });
            let mut app = empty_box(solver);
            // The second set meets only its own group, 0b1000.
            a.extend(b.into_iter().map(|(p, v, r, _, s)| {
                (p, v, r, Some(CollisionLayers::new(0b1000, 0b1000)), s)
            }));
            spawn_bodies(&mut app, &a);
            let kinds = kinds(&mut app);
            let mut hits = 0;
            for _ in 0..60 {
                app.update();
                let messages = app.world_mut().resource_mut::<Messages<CircleHit>>();
                for hit in messages.iter_current_update_messages() {
                    prop_assert!(
                        brute_meets(kinds[&hit.a], kinds[&hit.b]),
                        "{solver}: {:?} hit {:?}", kinds[&hit.a], kinds[&hit.b]
                    );
                    hits += 1;
                }
            }
            prop_assert!(hits > 10, "{solver}: {hits} hits test little");
            if solver.is_continuous() {
                let all: Vec<(Entity, DVec2, f64)> = app
                    .world_mut()
                    .query::<(Entity, &Position, &Radius)>()
                    .iter(app.world())
                    .map(|(e, p, r)| (e, p.0, r.0))
                    .collect();
                for (k, &(e, p, r)) in all.iter().enumerate() {
                    for &(f, q, s) in &all[k + 1..] {
                        if brute_meets(kinds[&e], kinds[&f]) {
                            prop_assert!(p.distance(q) > (r + s) * (1.0 - 1e-9), "{solver}");
                        }
                    }
                }
            }
        }
    }
}

/// Two circles of radius 0.5 head on at ±3, speed 1 (they touch at t = 2.5) under `solver`:
/// `before` changes them before the first step, `after` after one second, then two more
/// seconds run. Returns the app and the left circle.
fn head_on_course(
    solver: Solver,
    before: impl FnOnce(&mut World, Entity, Entity),
    after: impl FnOnce(&mut World, Entity, Entity),
) -> (App, Entity) {
    let mut app = empty_box(solver);
    let (a, b) = spawn_head_on(&mut app, 3.0, 1.0, 0.5);
    before(app.world_mut(), a, b);
    step(&mut app, 60); // 1 s: still 2 apart
    after(app.world_mut(), a, b);
    step(&mut app, 120);
    (app, a)
}

#[test]
fn layers_set_removed_or_a_sensor_added_by_game_code_take_effect_at_the_next_step() {
    let ghost = CollisionLayers::new(0b10, 0b10);
    let nothing = |_: &mut World, _: Entity, _: Entity| {};
    for solver in EVERY_SOLVER {
        // Passing through (the kept engine predicted no hit), then made to meet before they
        // touch: they bounce.
        let (app, a) = head_on_course(
            solver,
            |world, a, _| {
                world.entity_mut(a).insert(ghost);
            },
            |world, a, _| {
                world.entity_mut(a).remove::<CollisionLayers>();
            },
        );
        assert_eq!(pair_collisions(&app), 1, "{solver}: layers removed");
        assert!(state(&app, a).1.x < 0.0, "{solver}: a bounced back");

        // Meeting, then made a ghost before they touch: they pass through.
        let (app, a) = head_on_course(solver, nothing, |world, _, b| {
            world.entity_mut(b).insert(ghost);
        });
        assert_eq!(pair_collisions(&app), 0, "{solver}: layers set");
        assert_eq!(state(&app, a).1, DVec2::X, "{solver}: a flew on");

        // Made a sensor: the same.
        let (app, a) = head_on_course(solver, nothing, |world, _, b| {
            world.entity_mut(b).insert(Sensor);
        });
        assert_eq!(pair_collisions(&app), 0, "{solver}: made a sensor");
        assert_eq!(
            state(&app, a).1,
            DVec2::X,
            "{solver}: a flew through the sensor"
        );
    }
}

#[test]
fn an_engine_with_layers_predicts_no_event_for_a_pair_that_does_not_meet() {
    let circles = [
        CircleState::new(DVec2::new(-2.0, 0.0), DVec2::new(1.0, 0.0), 0.5),
        CircleState::new(DVec2::new(2.0, 0.0), DVec2::new(-1.0, 0.0), 0.5),
    ];
    let arena = Arena::centered(DVec2::splat(100.0)).with_boundary(Boundary::Open);
    let ghost = CollisionLayers::new(0b10, 0b10);
    for (layers, collisions) in [
        (vec![], 1),
        (vec![CollisionLayers::DEFAULT, ghost], 0),
        (vec![CollisionLayers::ALL, ghost], 1),
        (vec![ghost, CollisionLayers::NONE], 0),
        (vec![ghost, ghost], 1),
    ] {
        let mut engine = EventEngine::build_until(
            &circles,
            &arena,
            &[],
            (1.0, 1.0),
            (None, &[]),
            layers.clone(),
            || false,
        )
        .unwrap();
        engine.advance_to(4.0, u64::MAX).unwrap();
        assert_eq!(engine.stats().pair_collisions, collisions, "{layers:?}");
        // Setting layers afterwards predicts again: the same.
        let mut engine = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
        engine.set_layers(layers.clone());
        engine.advance_to(4.0, u64::MAX).unwrap();
        assert_eq!(engine.stats().pair_collisions, collisions, "{layers:?}");
    }
}

/// The sensors' overlaps by brute force: for each sensor, the circles (not sensors) nearer
/// than the sum of the radii whose layers meet the sensor's own, sorted.
fn brute_sensor_overlaps(app: &mut App) -> Vec<(Entity, Vec<Entity>)> {
    let all: Vec<(Entity, DVec2, f64, Option<CollisionLayers>, bool)> = app
        .world_mut()
        .query::<(
            Entity,
            &Position,
            &Radius,
            Option<&CollisionLayers>,
            Has<Sensor>,
        )>()
        .iter(app.world())
        .map(|(e, p, r, l, s)| (e, p.0, r.0, l.copied(), s))
        .collect();
    let mut found = Vec::new();
    for &(sensor, p, r, l, is_sensor) in &all {
        if !is_sensor {
            continue;
        }
        let (ms, fs) = masks(l);
        let mut inside: Vec<Entity> = all
            .iter()
            .filter(|&&(_, q, s, m, other_sensor)| {
                let (mc, fc) = masks(m);
                !other_sensor && p.distance(q) < r + s && ms & fc != 0 && mc & fs != 0
            })
            .map(|c| c.0)
            .collect();
        inside.sort_unstable();
        found.push((sensor, inside));
    }
    found.sort_unstable();
    found
}

#[test]
fn a_sensor_pushes_nothing_and_reports_exactly_the_circles_overlapping_it() {
    let picky = CollisionLayers::new(0b100, 0b100);
    for solver in EVERY_SOLVER {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        // A gas, one circle in five in the picky sensor's group only.
        let gas = grid_bodies(&mut rng, 48, DVec2::ZERO, |i, _| {
            ((i % 5 == 0).then_some(picky), false)
        });
        let sensors: Vec<(Body, bool)> = vec![
            // A still zone, a drifting one, a picky one (immovable: kinematic), and a small
            // movable one that bounces off the walls like any circle.
            ((DVec2::new(-1.0, 0.5), DVec2::ZERO, 0.9, None, true), true),
            (
                (
                    DVec2::new(2.0, -1.0),
                    DVec2::new(0.5, 0.25),
                    0.7,
                    None,
                    true,
                ),
                true,
            ),
            (
                (
                    DVec2::new(0.0, -2.0),
                    DVec2::new(-0.3, 0.0),
                    0.9,
                    Some(picky),
                    true,
                ),
                true,
            ),
            (
                (DVec2::new(3.0, 3.0), DVec2::new(-1.0, 2.0), 0.3, None, true),
                false,
            ),
        ];
        let mut with = empty_box(solver);
        let ids = spawn_bodies(&mut with, &gas);
        for &(body, immovable) in &sensors {
            let e = spawn_bodies(&mut with, &[body])[0];
            if immovable {
                with.world_mut().entity_mut(e).insert(Mass::IMMOVABLE);
            }
        }
        let mut without = empty_box(solver);
        let alone = spawn_bodies(&mut without, &gas);
        let mut before: Vec<(Entity, Vec<Entity>)> = brute_sensor_overlaps(&mut with)
            .into_iter()
            .map(|(s, _)| (s, Vec::new()))
            .collect();
        let (mut started_total, mut ended_total) = (0, 0);
        for n in 0..240 {
            with.update();
            without.update();
            let now = brute_sensor_overlaps(&mut with);
            let mut reported: Vec<(Entity, Vec<Entity>)> = with
                .world_mut()
                .query::<(Entity, &SensorOverlaps)>()
                .iter(with.world())
                .map(|(e, o)| (e, o.circles().to_vec()))
                .collect();
            reported.sort_unstable();
            assert_eq!(reported, now, "{solver}: step {n}");
            let mut started: Vec<(Entity, Entity)> = with
                .world()
                .resource::<Messages<OverlapStarted>>()
                .iter_current_update_messages()
                .map(|m| (m.sensor, m.circle))
                .collect();
            let mut ended: Vec<(Entity, Entity)> = with
                .world()
                .resource::<Messages<OverlapEnded>>()
                .iter_current_update_messages()
                .map(|m| (m.sensor, m.circle))
                .collect();
            started.sort_unstable();
            ended.sort_unstable();
            let (mut want_started, mut want_ended) = (Vec::new(), Vec::new());
            for ((s, was), (_, is)) in before.iter().zip(&now) {
                want_started.extend(is.iter().filter(|c| !was.contains(c)).map(|&c| (*s, c)));
                want_ended.extend(was.iter().filter(|c| !is.contains(c)).map(|&c| (*s, c)));
            }
            want_started.sort_unstable();
            want_ended.sort_unstable();
            assert_eq!(started, want_started, "{solver}: step {n}");
            assert_eq!(ended, want_ended, "{solver}: step {n}");
            started_total += started.len();
            ended_total += ended.len();
            before = now;
        }
        assert!(
            started_total > 15 && ended_total > 15,
            "{solver}: {started_total} started, {ended_total} ended test little"
        );
        assert_eq!(
            states(&with, &ids),
            states(&without, &alone),
            "{solver}: the sensors pushed a circle"
        );
    }
}

/// What a point query and a circle overlap query find, by brute force: circles in a group of
/// `mask`, sensors only if asked.
#[test]
fn spatial_queries_filter_by_membership_and_leave_sensors_out_on_request() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut app = empty_box(Solver::Discrete);
    let bodies = grid_bodies(&mut rng, 64, DVec2::ZERO, |_, rng| random_kind(rng));
    let ids = spawn_bodies(&mut app, &bodies);
    app.update();
    let mut checked = 0;
    for _ in 0..400 {
        let p = DVec2::new(rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0));
        let radius = rng.random_range(0.0..1.0);
        let mask = rng.random_range(0..16u32);
        let sensors = rng.random_bool(0.5);
        let mut filter = QueryFilter::circles_only().with_mask(mask);
        if !sensors {
            filter = filter.excluding_sensors();
        }
        let positions: Vec<DVec2> = ids.iter().map(|&e| state(&app, e).0).collect();
        let mut want: Vec<Entity> = ids
            .iter()
            .zip(&bodies)
            .zip(&positions)
            .filter(|((_, b), q)| {
                let memberships = b.3.map_or(1, |l| l.memberships);
                q.distance(p) < b.2 + radius && memberships & mask != 0 && (sensors || !b.4)
            })
            .map(|((&e, _), _)| e)
            .collect();
        want.sort_unstable();
        let mut got: Vec<Entity> = app
            .world_mut()
            .run_system_cached_with(
                |In((p, radius, filter)): In<(DVec2, f64, QueryFilter)>, query: SpatialQuery| {
                    query
                        .overlap_circle(p, radius, &filter)
                        .into_iter()
                        .filter_map(|t| match t {
                            Target::Circle(e) => Some(e),
                            Target::Wall(_) => None,
                        })
                        .collect::<Vec<_>>()
                },
                (p, radius, filter),
            )
            .unwrap();
        got.sort_unstable();
        checked += usize::from(!want.is_empty());
        assert_eq!(
            got, want,
            "at {p} within {radius}, mask {mask:#b}, sensors {sensors}"
        );
    }
    assert!(checked > 50, "{checked} queries found something");
}

#[test]
fn a_sensor_sweeping_through_a_sleeping_heap_wakes_none_of_it() {
    for solver in [Solver::Discrete, Solver::Substeps(4), Solver::Soft(4)] {
        let mut app = create_app(CirclesConfig {
            arena: Arena::centered(DVec2::new(8.0, 8.0)),
            solver,
            spawn: SpawnConfig {
                count: 0,
                ..default()
            },
            effects: Effects {
                gravity: Some(DVec2::new(0.0, -9.81)),
                restitution: 0.0,
                wall_restitution: 0.0,
                ..default()
            },
            ..default()
        });
        // A row of balls on the floor.
        for k in 0..6 {
            let x = -2.5 + k as f64;
            spawn_circle(&mut app, DVec2::new(x, -3.6), DVec2::ZERO, 0.4, 1.0);
        }
        step(&mut app, 240);
        let asleep = |app: &App| app.world().resource::<Sleeping>().count;
        assert_eq!(asleep(&app), 6, "{solver}: the row fell asleep");
        // A kinematic sensor sweeping along the row through every ball.
        app.world_mut().spawn((
            Radius(0.5),
            Position(DVec2::new(-3.5, -3.6)),
            Velocity(DVec2::new(2.0, 0.0)),
            Mass::IMMOVABLE,
            Sensor,
        ));
        for n in 0..180 {
            app.update();
            assert_eq!(
                asleep(&app),
                6,
                "{solver}: step {n}, the sensor woke a ball"
            );
        }
    }
}

#[test]
fn a_checkpoint_of_an_exact_run_with_a_wide_sensor_resumes() {
    // The engine's cells are sized without the sensor: the checkpoint keeps no engine, the
    // resumed run builds one, and the zone comes back as a sensor (once it came back as a
    // plain circle, and before that the resume was refused as inconsistent).
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut app = empty_box(Solver::Exact);
    spawn_bodies(
        &mut app,
        &grid_bodies(&mut rng, 48, DVec2::ZERO, |_, _| (None, false)),
    );
    let zone = (DVec2::new(0.5, 0.5), DVec2::new(0.2, 0.1), 2.5, None, true);
    spawn_bodies(&mut app, &[zone]);
    let progress = Progress::start(app.world_mut());
    step(&mut app, 20);
    let bytes = Checkpoint::take(app.world_mut(), "zone", &progress).to_bytes();
    let checkpoint = Checkpoint::from_bytes(&bytes, "zone.checkpoint")
        .unwrap_or_else(|e| panic!("our own checkpoint is refused: {e}"));
    let (mut resumed, _) = checkpoint
        .resume("zone.checkpoint")
        .unwrap_or_else(|e| panic!("our own checkpoint does not resume: {e}"));
    let world = resumed.world_mut();
    assert_eq!(world.query::<&Sensor>().iter(world).count(), 1);
    step(&mut resumed, 20);
    assert_eq!(
        resumed.world().resource::<CircleDiagnostics>().non_finite,
        0
    );
}
