//! Collision messages: under every solver, a game system reading `CircleHit` and `WallHit` sees
//! exactly the hits the report counts, with sensible contents, in time order within a step;
//! with messages off it sees none. Per-circle restitution combines as documented.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::prelude::*;

/// What a game-side reader collected: every message, tagged with the step it arrived in.
#[derive(Resource, Default)]
struct Heard {
    circles: Vec<(u64, CircleHit)>,
    walls: Vec<(u64, WallHit)>,
}

fn listen(
    totals: Res<StepTotals>,
    mut heard: ResMut<Heard>,
    mut circle_hits: MessageReader<CircleHit>,
    mut wall_hits: MessageReader<WallHit>,
) {
    let step = totals.steps;
    heard.circles.extend(circle_hits.read().map(|&h| (step, h)));
    heard.walls.extend(wall_hits.read().map(|&h| (step, h)));
}

/// A small walled gas under `solver`, with a listener in `Update` as a game would add one.
fn gas(solver: &str, messages: bool) -> App {
    let mut app = scene_app(&format!(
        "(solver: \"{solver}\", arena: (size: (8.0, 6.0), boundary: walls),
          effects: (collisions: true, hit_messages: {messages}, restitution: 0.9),
          spawn: (count: 40, radius: (0.15, 0.3), speed: (2.0, 6.0), seed: 7))"
    ));
    app.init_resource::<Heard>().add_systems(Update, listen);
    app
}

#[test]
fn every_counted_hit_is_one_message_under_every_solver() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = gas(solver, true);
        step(&mut app, 120);
        let dt = app
            .world()
            .resource::<Time<Fixed>>()
            .timestep()
            .as_secs_f64();
        let arena = *app.world().resource::<Arena>();
        let heard = app.world().resource::<Heard>();
        let pairs = app.world().resource::<PairCollisions>().count;
        let walls = app.world().resource::<WallCollisions>().count;
        assert!(
            pairs > 20 && walls > 20,
            "{solver}: {pairs} pairs, {walls} walls"
        );
        assert_eq!(heard.circles.len() as u64, pairs, "{solver}: circle hits");
        let wall_hits: u64 = heard.walls.iter().map(|(_, h)| h.count).sum();
        assert_eq!(wall_hits, walls, "{solver}: wall hits");
        for (_, h) in &heard.circles {
            assert_ne!(h.a, h.b, "{solver}");
            assert!((h.normal.length() - 1.0).abs() < 1e-9, "{solver}: {h:?}");
            assert!(h.impulse > 0.0 && h.normal_speed > 0.0, "{solver}: {h:?}");
            assert!(
                (0.0..=dt * (1.0 + 1e-9)).contains(&h.time),
                "{solver}: {h:?}"
            );
            // e = 0.9, equal-density circles: j = (1 + e) v_n / (1/m_a + 1/m_b). `soft`
            // reports the whole step's push, which other contacts of the circles in the same
            // step share: only an isolated hit matches it.
            let mass = |e: Entity| app.world().get::<Mass>(e).unwrap().0;
            let expected = 1.9 * h.normal_speed / (1.0 / mass(h.a) + 1.0 / mass(h.b));
            if !is_soft(solver) {
                assert_relative(solver, h.impulse, expected, 1e-9);
            }
        }
        for (_, h) in &heard.walls {
            let Wall::Arena(wall) = h.wall else {
                panic!("{solver}: a segment wall hit without segments: {h:?}");
            };
            let (_, normal) = wall.contact(h.point, &arena);
            assert_eq!(h.normal, normal, "{solver}: {h:?}");
            assert!(h.impulse > 0.0 && h.normal_speed > 0.0, "{solver}: {h:?}");
            let on_wall = match wall {
                ArenaWall::Left => h.point.x == -4.0,
                ArenaWall::Right => h.point.x == 4.0,
                ArenaWall::Bottom => h.point.y == -3.0,
                ArenaWall::Top => h.point.y == 3.0,
            };
            assert!(on_wall, "{solver}: {h:?}");
        }
        if is_continuous(solver) {
            // Event times, in the order they happened within each step.
            let circle_times: Vec<_> = heard.circles.iter().map(|(s, h)| (*s, h.time)).collect();
            let wall_times: Vec<_> = heard.walls.iter().map(|(s, h)| (*s, h.time)).collect();
            for times in [circle_times, wall_times] {
                assert!(times.is_sorted(), "{solver}: hits out of time order");
            }
            assert!(
                heard
                    .circles
                    .iter()
                    .any(|(_, h)| h.time > 0.0 && h.time < dt * 0.99),
                "{solver}: no hit inside a step"
            );
        } else {
            // The discrete solvers at the end of the substep; `soft` at the end of the part of
            // the step that resolved it (a step split into up to 64 equal parts where a circle
            // would move too far in one).
            let parts: Vec<f64> = if is_soft(solver) {
                (1..=64).map(f64::from).collect()
            } else if solver == "substeps=4" {
                vec![4.0]
            } else {
                vec![1.0]
            };
            for (_, h) in &heard.circles {
                let on_an_end = parts.iter().any(|&n| {
                    let k = h.time / (dt / n);
                    (k - k.round()).abs() < 1e-6 && k.round() >= 1.0
                });
                assert!(on_an_end, "{solver}: {h:?}");
            }
        }
    }
}

#[test]
fn without_messages_nothing_is_written_and_nothing_changes() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let (mut on, mut off) = (gas(solver, true), gas(solver, false));
        step(&mut on, 60);
        step(&mut off, 60);
        let heard = off.world().resource::<Heard>();
        assert!(
            heard.circles.is_empty() && heard.walls.is_empty(),
            "{solver}"
        );
        assert!(pair_collisions(&off) > 0, "{solver}");
        // Recording hits does not change the simulation.
        assert_eq!(state_hash(&mut on), state_hash(&mut off), "{solver}");
    }
}

#[test]
fn a_circle_restitution_combines_with_the_scene_as_the_minimum() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        // Two circles head-on (v = ±1) in a wide box; one has its own restitution 0.5.
        let mut app = scene_app(&format!(
            "(solver: \"{solver}\", arena: (size: (20.0, 4.0), boundary: walls),
              effects: (restitution: 0.8, wall_restitution: 0.3), spawn: (count: 0))"
        ));
        let (a, b) = spawn_head_on(&mut app, 1.0, 1.0, 0.25);
        app.world_mut().entity_mut(a).insert(Restitution(0.5));
        step(&mut app, 60);
        // min(0.5, 0.8) = 0.5: relative speed 2 becomes 1, equal masses: ±0.5.
        let (va, vb) = (state(&app, a).1.x, state(&app, b).1.x);
        assert!(
            (va + 0.5).abs() < 1e-9 && (vb - 0.5).abs() < 1e-9,
            "{solver}: {va} {vb}"
        );
        // A third circle with restitution 0.9 against walls of 0.3 bounces with 0.3; and one
        // of 0.1 with 0.1.
        for (own, expected) in [(0.9, 0.3), (0.1, 0.1)] {
            let c = spawn_circle(&mut app, DVec2::new(0.0, 1.0), DVec2::Y, 0.25, 1.0);
            app.world_mut().entity_mut(c).insert(Restitution(own));
            step(&mut app, 60);
            let v = state(&app, c).1;
            assert!((v.y + expected).abs() < 1e-9, "{solver}: own {own}: {v}");
            app.world_mut().despawn(c);
        }
    }
}

#[test]
fn a_restitution_given_in_flight_takes_effect_at_the_next_hit() {
    for solver in SOLVERS {
        let solver = &*solver.to_string();
        let mut app = scene_app(&format!(
            "(solver: \"{solver}\", arena: (size: (4.0, 4.0), boundary: walls),
              effects: (wall_restitution: 1.0), spawn: (count: 0))"
        ));
        // Rising at 1 from the centre: it meets the top wall (y = 1.75) after 1.75 s.
        let c = spawn_circle(&mut app, DVec2::ZERO, DVec2::Y, 0.25, 1.0);
        step(&mut app, 10);
        app.world_mut().entity_mut(c).insert(Restitution(0.5));
        step(&mut app, 110);
        let v = state(&app, c).1;
        assert!((v.y + 0.5).abs() < 1e-9, "{solver}: {v}");
    }
}
