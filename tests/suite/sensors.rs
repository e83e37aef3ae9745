//! Sensors under every solver, against brute force: a sensor pushes nothing and reports
//! exactly the circles overlapping it, step by step, wakes nothing it sweeps through, and
//! resumes from a checkpoint of `exact`; spatial queries filter by membership and leave
//! sensors out on request.

use crate::collision_layers::{
    Body, empty_box, grid_bodies, masks, random_kind, spawn_bodies, states,
};
use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::arena::Arena;
use moving_circles::prelude::*;
use moving_circles::tools::checkpoint::Checkpoint;
use moving_circles::tools::run::Progress;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

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
    for solver in SOLVERS {
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
