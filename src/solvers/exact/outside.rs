//! What user code did to the circles of the engine `exact` keeps since it last wrote them
//! back ([`moved_since`]): the few it moved, steered or turned, which the engine takes in
//! place, or why it must be built anew.

use bevy::ecs::entity::EntityHashMap;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::engine::EventEngine;
use crate::base::components::{Restitution, SolverCircles, SpinCircles};

/// What user code did to one circle of a kept engine since it last wrote it back.
pub(super) struct Moved {
    pub index: usize,
    /// Moved or steered it: its new position and velocity.
    pub motion: Option<(DVec2, DVec2)>,
    /// Turned it (in a rough engine): its new spin and angle.
    pub turn: Option<(f64, f64)>,
}

/// How one circle turns, as its components say: spin and angle (0 for what it lacks), and its
/// own moment of inertia.
#[derive(Clone, Copy)]
pub(super) struct Turning {
    pub turn: (f64, f64),
    pub inertia: Option<f64>,
}

/// Of the `changed` circles (written since the kept `engine` last wrote them, or spawned), with
/// how each turns now (in a rough engine; none in a smooth one), those user code moved,
/// steered or turned; or why the engine cannot be kept (a circle came, went, or changed its
/// radius, mass, restitution or moment of inertia). `known` holds how many circles the engine
/// has and each one's index by entity.
pub(super) fn moved_since(
    engine: &EventEngine,
    known: (usize, &EntityHashMap<usize>),
    (changed, turned): (&[Entity], &[Turning]),
    circles: &SolverCircles,
    restitution_of: impl Fn(Option<&Restitution>) -> f64,
) -> Result<Vec<Moved>, &'static str> {
    let (count, index) = known;
    if circles.iter().len() != count {
        return Err("circles were spawned or despawned");
    }
    let mut moved = Vec::new();
    for (k, &entity) in changed.iter().enumerate() {
        let (Some(&i), Ok((_, p, v, r, m, e, ..))) = (index.get(&entity), circles.get(entity))
        else {
            return Err("circles were spawned or despawned");
        };
        if engine.body(i) != (r.0, m.inverse(), restitution_of(e)) {
            return Err("a radius, mass or restitution changed");
        }
        let motion = ((p.0, v.0) != (engine.position(i), engine.velocity(i))).then_some((p.0, v.0));
        let turning = turned.get(k);
        if turning.is_some_and(|t| t.inertia != engine.own_inertia(i)) {
            return Err("a moment of inertia changed");
        }
        let turn = turning
            .map(|t| t.turn)
            .filter(|&t| Some(t) != engine.turn(i));
        if motion.is_some() || turn.is_some() {
            moved.push(Moved {
                index: i,
                motion,
                turn,
            });
        }
    }
    Ok(moved)
}

/// How each of `entities` turns now.
pub(super) fn turning_of(
    spins: &SpinCircles,
    entities: impl Iterator<Item = Entity>,
) -> Vec<Turning> {
    entities
        .map(|entity| match spins.get(entity) {
            Ok((spin, angle, _, own, _)) => Turning {
                turn: (spin.map_or(0.0, |w| w.0), angle.map_or(0.0, |a| a.0)),
                inertia: own.map(|i| i.0),
            },
            Err(_) => Turning {
                turn: (0.0, 0.0),
                inertia: None,
            },
        })
        .collect()
}
