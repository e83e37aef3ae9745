//! Body kinds and circles that come and go, under every solver: a static peg never moves and
//! deflects what hits it; a kinematic paddle steered by user code pushes circles and what it
//! gave them is counted; user systems spawn, despawn, teleport and resize circles between steps
//! with no overlap and no stale event.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::circle::snapshot_with_entities;
use moving_circles::kernels::overlapping_circles;
use moving_circles::prelude::*;
use moving_circles::solvers::exact::EngineState;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn empty_scene(solver: &str, arena: &str, effects: &str) -> App {
    scene_app(&format!(
        "(solver: \"{solver}\", arena: {arena}, effects: ({effects}), spawn: (count: 0))"
    ))
}

/// Kinetic energy and momentum of the movable circles.
fn movable_energy_momentum(app: &mut App) -> (f64, DVec2) {
    circles(app)
        .into_iter()
        .filter(|c| c.3.is_finite())
        .fold((0.0, DVec2::ZERO), |(e, p), (_, v, _, m)| {
            (e + 0.5 * m * v.length_squared(), p + m * v)
        })
}

#[test]
fn a_static_peg_deflects_circles_and_never_moves() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = empty_scene(
            solver,
            "(size: (12.0, 12.0), boundary: walls)",
            "gravity: (0.0, -1.0)",
        );
        let peg = spawn_circle(&mut app, DVec2::ZERO, DVec2::ZERO, 0.3, f64::INFINITY);
        // Balls dropped onto the peg, slightly off centre.
        for (k, x) in [-0.2, 0.05, 0.25].into_iter().enumerate() {
            spawn_circle(
                &mut app,
                DVec2::new(x, 1.0 + k as f64),
                DVec2::ZERO,
                0.2,
                1.0,
            );
        }
        step(&mut app, 240);
        assert_eq!(state(&app, peg), (DVec2::ZERO, DVec2::ZERO), "{solver}");
        let counted = *app.world().resource::<PairCollisions>();
        assert!(counted.count >= 3, "{solver}: {counted:?}");
        // An elastic hit off a peg at rest changes no speed: it gives no energy.
        let scale = 0.5 * 9.0;
        assert!(
            counted.immovable_work.abs() < 1e-9 * scale,
            "{solver}: {counted:?}"
        );
        assert!(
            counted.immovable_impulse.length() > 0.1,
            "{solver}: {counted:?}"
        );
        for (p, ..) in circles(&mut app).into_iter().filter(|c| c.3.is_finite()) {
            assert!(
                p.distance(DVec2::ZERO) >= 0.5 - 1e-6,
                "{solver}: a ball in the peg: {p}"
            );
        }
    }
}

/// The paddle's velocity, set by "user code" before every step: forward at 2, weaving up and
/// down, so the event engine sees it changed from outside every step.
#[derive(Resource)]
struct Paddle(Entity);

fn steer(paddle: Res<Paddle>, totals: Res<StepTotals>, mut velocities: Query<&mut Velocity>) {
    let weave = (totals.steps as f64 * 0.3).sin();
    velocities.get_mut(paddle.0).unwrap().0 = DVec2::new(2.0, 0.5 * weave);
}

#[test]
fn a_kinematic_paddle_pushes_circles_and_its_work_is_counted() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = empty_scene(solver, "(size: (40.0, 20.0), boundary: periodic)", "");
        let paddle = spawn_circle(&mut app, DVec2::new(-15.0, 0.0), DVec2::ZERO, 1.0, 1.0);
        app.world_mut().entity_mut(paddle).insert(Mass::IMMOVABLE);
        app.insert_resource(Paddle(paddle))
            .add_systems(FixedUpdate, steer.before(CircleSystems::Step));
        // A column of resting circles in the paddle's way, and a few that move.
        for k in 0..8 {
            let y = -1.4 + 0.4 * k as f64;
            spawn_circle(&mut app, DVec2::new(-10.0, y), DVec2::ZERO, 0.15, 1.0);
            spawn_circle(
                &mut app,
                DVec2::new(-6.0, y),
                DVec2::new(-0.5, 0.1),
                0.15,
                2.0,
            );
        }
        let (e0, p0) = movable_energy_momentum(&mut app);
        step(&mut app, 180);
        let (e1, p1) = movable_energy_momentum(&mut app);
        let counted = *app.world().resource::<PairCollisions>();
        assert!(counted.immovable_work > 1.0, "{solver}: {counted:?}");
        // Elastic hits among the circles keep their energy and momentum: every change is what
        // the paddle gave.
        assert_relative(solver, e1 - e0, counted.immovable_work, 1e-9);
        assert!(
            (p1 - p0 - counted.immovable_impulse).length() < 1e-9 * p1.length(),
            "{solver}: momentum {p0} -> {p1}, paddle gave {}",
            counted.immovable_impulse
        );
        // Nothing pushed the paddle back: it moved exactly as steered.
        let moved = state(&app, paddle).0.x + 15.0;
        assert!(
            (moved - 2.0 * 3.0).abs() < 1e-6,
            "{solver}: paddle moved {moved}"
        );
        if solver == "exact" {
            let engine = app.world().resource::<EngineState>();
            assert_eq!(
                engine.rebuilds, 1,
                "{solver}: the steered paddle rebuilt the engine"
            );
            assert!(
                engine.updates >= 179,
                "{solver}: {} updates",
                engine.updates
            );
        }
    }
}

/// A spot in `arena` clear of every circle by `margin`, for a circle of radius `r`.
fn free_spot(app: &mut App, rng: &mut ChaCha8Rng, r: f64, margin: f64) -> DVec2 {
    let taken = circles(app);
    let arena = *app.world().resource::<Arena>();
    loop {
        let p = DVec2::new(
            rng.random_range(arena.min.x + r..arena.max.x - r),
            rng.random_range(arena.min.y + r..arena.max.y - r),
        );
        if taken
            .iter()
            .all(|&(q, _, rq, _)| p.distance(q) > r + rq + margin)
        {
            return p;
        }
    }
}

#[test]
fn circles_come_and_go_between_steps_under_every_solver() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = empty_scene(
            solver,
            "(size: (6.0, 4.0), boundary: walls)",
            "hit_messages: true",
        );
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut alive: Vec<Entity> = Vec::new();
        for _ in 0..12 {
            let p = free_spot(&mut app, &mut rng, 0.2, 0.05);
            let v = DVec2::from_angle(rng.random_range(0.0..6.3)) * 3.0;
            alive.push(spawn_circle(&mut app, p, v, 0.2, 1.0));
        }
        let mut gone: Vec<Entity> = Vec::new();
        let mut deepest: f64 = 0.0;
        for k in 0..600 {
            // One comes, one goes.
            let p = free_spot(&mut app, &mut rng, 0.2, 0.05);
            let v = DVec2::from_angle(rng.random_range(0.0..6.3)) * 3.0;
            alive.push(spawn_circle(&mut app, p, v, 0.2, 1.0));
            let out = alive.remove(rng.random_range(0..alive.len()));
            app.world_mut().despawn(out);
            gone.push(out);
            let pick = alive[rng.random_range(0..alive.len())];
            match k % 3 {
                // Teleport to a free spot with a new velocity.
                0 => {
                    let p = free_spot(&mut app, &mut rng, 0.35, 0.05);
                    let mut e = app.world_mut().entity_mut(pick);
                    e.insert((Position(p), Velocity(DVec2::new(-2.0, 1.0))));
                }
                // Grow a circle that has room, and make it heavier.
                1 => {
                    let (q, r) = {
                        let e = app.world().entity(pick);
                        (e.get::<Position>().unwrap().0, e.get::<Radius>().unwrap().0)
                    };
                    let arena = *app.world().resource::<Arena>();
                    let grown = (r * 1.25).min(0.35);
                    let room = circles(&mut app)
                        .iter()
                        .filter(|c| c.0 != q)
                        .all(|c| c.0.distance(q) > c.2 + grown + 0.01)
                        && arena.contains(q - DVec2::splat(grown))
                        && arena.contains(q + DVec2::splat(grown));
                    if room {
                        app.world_mut()
                            .entity_mut(pick)
                            .insert((Radius(grown), Mass(4.0)));
                    }
                }
                // Only a new velocity.
                _ => {
                    let v = DVec2::from_angle(rng.random_range(0.0..6.3)) * 4.0;
                    app.world_mut().entity_mut(pick).insert(Velocity(v));
                }
            }
            app.update();
            // No message names a circle that is gone.
            let hits = app.world().resource::<Messages<CircleHit>>();
            for h in hits.iter_current_update_messages() {
                assert!(
                    !gone.contains(&h.a) && !gone.contains(&h.b),
                    "{solver}: {h:?}"
                );
            }
            let arena = *app.world().resource::<Arena>();
            let now = snapshot_with_entities(app.world_mut());
            assert_eq!(now.len(), 12, "{solver}");
            let discs: Vec<_> = now.iter().map(|(_, c)| (c.position, c.radius)).collect();
            for (i, j, depth) in overlapping_circles(&discs, &arena, &[]) {
                deepest = deepest.max(depth / discs[i].1.min(discs[j].1));
            }
        }
        // The continuous solvers never let circles overlap; the discrete ones resolve what
        // they find within the step.
        let bound = if is_continuous(solver) { 1e-9 } else { 0.2 };
        assert!(
            deepest <= bound,
            "{solver}: deepest overlap {deepest} radii"
        );
        assert!(
            pair_collisions(&app) > 50,
            "{solver}: {}",
            pair_collisions(&app)
        );
    }
}

#[test]
fn a_scene_declares_static_pegs_and_refuses_moving_or_weighed_ones() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = scene_app(&format!(
            "(solver: \"{solver}\", arena: (size: (6.0, 6.0), boundary: walls),
              effects: (gravity: (0.0, -4.0), restitution: 0.7),
              circles: [(position: (0.0, 0.0), radius: 0.4, immovable: true),
                        (position: (0.1, 2.0), radius: 0.2)])"
        ));
        step(&mut app, 120);
        let all = circles(&mut app);
        assert_eq!(
            (all[0].0, all[0].1, all[0].3),
            (DVec2::ZERO, DVec2::ZERO, f64::INFINITY)
        );
        assert!(
            all[1].0.distance(DVec2::ZERO) >= 0.6 - 1e-6,
            "{solver}: {:?}",
            all[1]
        );
        assert!(pair_collisions(&app) > 0, "{solver}");
    }
    for (extra, field) in [
        ("mass: 2.0", "circles[0].mass"),
        ("velocity: (1.0, 0.0)", "circles[0].velocity"),
    ] {
        let text =
            format!("(circles: [(position: (0.0, 0.0), radius: 0.4, immovable: true, {extra})])");
        let err = Scene::parse(&text, "pegs.ron")
            .and_then(|s| s.to_config("pegs.ron"))
            .unwrap_err()
            .to_string();
        assert!(err.contains(&format!("pegs.ron: field `{field}`")), "{err}");
    }
}
