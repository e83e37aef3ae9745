//! What a circle has of its own that no scene gives it, only code: its restitution, friction
//! coefficient, moment of inertia, collision layers, and being a sensor (with the circles it
//! overlapped after the last step, which decide its next overlap messages). A checkpoint keeps
//! them for the circles that have any ([`OwnParts`]), checks them as it checks every value, and
//! puts them back on the resumed circles.

use bevy::ecs::entity::EntityHashMap;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::collision_layers::{CollisionLayers, Sensor, SensorOverlaps};
use crate::base::components::{Friction, Inertia, Restitution};
use crate::base::config::MAX_FRICTION;

/// The parts of its own one circle has (at least one of them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct OwnParts {
    /// The circle, as its place in the checkpoint's circles.
    pub(super) circle: u32,
    pub(super) restitution: Option<f64>,
    pub(super) friction: Option<f64>,
    pub(super) inertia: Option<f64>,
    pub(super) layers: Option<CollisionLayers>,
    /// As a sensor, the circles it overlapped (their places, increasing).
    pub(super) sensor: Option<Vec<u32>>,
}

/// The circles' own parts, read from `world` for `entities` (the checkpoint's circles, in
/// order); circles with none are left out.
pub(super) fn gather(world: &World, entities: &[Entity]) -> Vec<OwnParts> {
    // Made the first time a sensor needs it.
    let places = std::cell::OnceCell::<EntityHashMap<u32>>::new();
    let place = |e: &Entity| {
        let places = places.get_or_init(|| (0..).zip(entities).map(|(i, &e)| (e, i)).collect());
        places.get(e).copied()
    };
    let mut own = Vec::new();
    for (i, &entity) in entities.iter().enumerate() {
        let e = world.entity(entity);
        let sensor = e.get::<Sensor>().map(|_| {
            let overlaps = e.get::<SensorOverlaps>();
            let mut places: Vec<u32> = overlaps
                .map_or(&[][..], SensorOverlaps::circles)
                .iter()
                .filter_map(place)
                .collect();
            places.sort_unstable();
            places
        });
        let parts = OwnParts {
            circle: i as u32,
            restitution: e.get::<Restitution>().map(|r| r.0),
            friction: e.get::<Friction>().map(|f| f.0),
            inertia: e.get::<Inertia>().map(|i| i.0),
            layers: e.get::<CollisionLayers>().copied(),
            sensor,
        };
        let any = parts.restitution.is_some()
            || parts.friction.is_some()
            || parts.inertia.is_some()
            || parts.layers.is_some()
            || parts.sensor.is_some();
        if any {
            own.push(parts);
        }
    }
    own
}

/// Whether `own` fits `circles` circles: each named once, in increasing order, within range;
/// restitutions in `[0, 1]`, friction from 0 to [`MAX_FRICTION`] (the ranges the components
/// document), moments of inertia numbers; a sensor's overlaps other circles that are not
/// sensors, in increasing order.
pub(super) fn check(own: &[OwnParts], circles: usize) -> Result<(), String> {
    let sensors: Vec<u32> = own
        .iter()
        .filter(|p| p.sensor.is_some())
        .map(|p| p.circle)
        .collect();
    let mut last = None;
    for parts in own {
        let i = parts.circle;
        if last.is_some_and(|last| i <= last) || i as usize >= circles {
            return Err(format!(
                "its circles' own parts name circle {i} out of order or range"
            ));
        }
        last = Some(i);
        let wrong = |what: &str, value: f64| format!("circle {i}'s own {what} is {value:?}");
        if let Some(e) = parts.restitution.filter(|e| !(0.0..=1.0).contains(e)) {
            return Err(wrong("restitution", e) + ", not in [0, 1]");
        }
        if let Some(f) = parts.friction.filter(|f| !(0.0..=MAX_FRICTION).contains(f)) {
            return Err(wrong("friction", f) + &format!(", not in [0, {MAX_FRICTION}]"));
        }
        if let Some(inertia) = parts.inertia.filter(|i| i.is_nan()) {
            return Err(wrong("moment of inertia", inertia));
        }
        if let Some(overlaps) = &parts.sensor {
            let increasing = overlaps.windows(2).all(|w| w[0] < w[1]);
            let wrong = |k: &u32| *k as usize >= circles || sensors.binary_search(k).is_ok();
            if !increasing || overlaps.iter().any(wrong) {
                return Err(format!(
                    "sensor circle {i} overlaps circles out of order or range"
                ));
            }
        }
    }
    Ok(())
}

/// Puts `own` back on the circles `entities` (the checkpoint's circles, in order, as resumed).
///
/// Bevy groups entities by the components they have, so the resumed world's tables may come
/// in another order than the paused one's; the solvers take the circles in serial order (the
/// checkpoint's order, in which the circles are spawned again), so the run resumes bit for bit
/// whatever parts the circles have.
pub(super) fn apply(own: &[OwnParts], world: &mut World, entities: &[Entity]) {
    for parts in own {
        let mut e = world.entity_mut(entities[parts.circle as usize]);
        if let Some(r) = parts.restitution {
            e.insert(Restitution(r));
        }
        if let Some(f) = parts.friction {
            e.insert(Friction(f));
        }
        if let Some(i) = parts.inertia {
            e.insert(Inertia(i));
        }
        if let Some(layers) = parts.layers {
            e.insert(layers);
        }
        if let Some(overlaps) = &parts.sensor {
            let mut overlapping: Vec<Entity> =
                overlaps.iter().map(|&k| entities[k as usize]).collect();
            overlapping.sort_unstable();
            e.insert((Sensor, SensorOverlaps(overlapping)));
        }
    }
}

/// Each circle's restitution (its own or `default`), or none if no circle has its own: what
/// the `exact` engine keeps beside its snapshot.
pub(super) fn restitutions(own: &[OwnParts], circles: usize, default: f64) -> Vec<f64> {
    if own.iter().all(|p| p.restitution.is_none()) {
        return Vec::new();
    }
    let mut all = vec![default; circles];
    for parts in own {
        if let Some(r) = parts.restitution {
            all[parts.circle as usize] = r;
        }
    }
    all
}
