//! A step's bits do not depend on how Bevy lays the circles out: circles moved to other tables
//! (a component of the user's own put on and taken off, which reorders the tables) step to
//! exactly the bits of the same circles left alone, under every solver, because every solver
//! visits circles by their serial (the spawn order), not in query order.

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::circle::snapshot;
use moving_circles::prelude::*;

/// A component of the user's own.
#[derive(Component)]
struct Tag;

/// Rough, frictional circles of a few restitutions falling into a box, hitting each other and
/// the walls, some of them going to sleep: what every solver's contact order matters for.
fn falling_box(solver: Solver) -> App {
    let mut app = create_app(CirclesConfig {
        arena: Arena::centered(DVec2::new(4.0, 3.0)),
        spawn: SpawnConfig {
            count: 60,
            radius: (0.1, 0.2),
            speed: (1.0, 3.0),
            seed: 21,
            ..default()
        },
        effects: Effects {
            gravity: Some(DVec2::new(0.0, -9.81)),
            friction: 0.4,
            restitution: 0.8,
            ..default()
        },
        solver,
        ..default()
    });
    let world = app.world_mut();
    let entities: Vec<Entity> = world
        .query_filtered::<Entity, With<Radius>>()
        .iter(world)
        .collect();
    for (i, &e) in entities.iter().enumerate() {
        if i % 5 == 0 {
            world.entity_mut(e).insert(Restitution(0.3));
        }
    }
    app
}

/// The circles' entities in query order.
fn query_order(app: &mut App) -> Vec<Entity> {
    let world = app.world_mut();
    world
        .query_filtered::<Entity, With<Radius>>()
        .iter(world)
        .collect()
}

#[test]
fn circles_moved_between_tables_step_to_the_same_bits_under_every_solver() {
    let mut differing = Vec::new();
    for solver in SOLVERS {
        let mut left = falling_box(solver);
        let mut moved = falling_box(solver);
        step(&mut left, 20);
        step(&mut moved, 20);
        // Every third circle leaves its table and comes back at its end: the query now
        // yields the circles in another order than they were spawned in.
        let before = query_order(&mut moved);
        let world = moved.world_mut();
        for &e in before.iter().step_by(3) {
            world.entity_mut(e).insert(Tag);
        }
        for &e in before.iter().step_by(3) {
            world.entity_mut(e).remove::<Tag>();
        }
        assert_ne!(
            query_order(&mut moved),
            before,
            "{solver}: the tables kept their order"
        );
        step(&mut left, 40);
        step(&mut moved, 40);
        let (left, moved) = (snapshot(left.world_mut()), snapshot(moved.world_mut()));
        assert!(
            left.iter().any(|c| c.velocity != DVec2::ZERO),
            "{solver}: nothing moves"
        );
        let (left, moved) = (state_bits(&left), state_bits(&moved));
        assert_eq!(left.len(), moved.len(), "{solver}");
        let differ = left.iter().zip(&moved).filter(|(a, b)| a != b).count();
        if differ > 0 {
            differing.push(format!("{solver}: {differ} of {} circles", left.len()));
        }
    }
    assert!(differing.is_empty(), "not the same bits: {differing:?}");
}
