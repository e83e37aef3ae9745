//! Sensors at work: after each fixed step, [`SensorPlugin`] finds the circles overlapping each
//! [`Sensor`] ([`sensor_overlaps`], on an index of the sensors, so the cost is one look per
//! circle whatever the number of sensors), keeps them in the sensor's [`SensorOverlaps`] and
//! writes an [`OverlapStarted`] or [`OverlapEnded`] message for each circle that came or went.
//! Overlaps are those of the state at the end of the step, under every solver: a circle that
//! flies through a sensor within one step is not seen.
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! let mut app = moving_circles::tools::run::headless_app(CirclesConfig::default());
//! let zone = app.world_mut().spawn((
//!     Radius(1.0),
//!     Position(DVec2::ZERO),
//!     Mass::IMMOVABLE,
//!     Sensor,
//! )).id();
//! let ball = app.world_mut().spawn((
//!     Radius(0.25),
//!     Position(DVec2::new(-3.0, 0.0)),
//!     Velocity(DVec2::new(1.0, 0.0)),
//! )).id();
//! for _ in 0..120 {
//!     app.update(); // 2 s of 1/60 s steps: the ball is well inside by now
//! }
//! assert!(app.world().get::<SensorOverlaps>(zone).unwrap().contains(ball));
//! // It flew straight in: the zone pushed it not at all.
//! assert_eq!(app.world().get::<Velocity>(ball).unwrap().0, DVec2::new(1.0, 0.0));
//! ```

use bevy::ecs::schedule::common_conditions::any_with_component;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{
    CollisionLayers, OverlapEnded, OverlapStarted, Sensor, SensorOverlaps,
};
use crate::base::components::{Position, Radius};
use crate::game::query::index::CircleIndex;
use crate::step::schedule::CircleSystems;

/// Finds what overlaps each sensor after every fixed step, in [`CircleSystems::Sensors`]
/// (part of [`CirclesPlugins`](crate::CirclesPlugins)), and registers [`CollisionLayers`] and
/// [`Sensor`] for reflection. A world without sensors runs nothing.
///
/// A sensor still moves with its velocity: make it
/// [`Mass::IMMOVABLE`](crate::base::components::Mass::IMMOVABLE) for a fixed or steered zone.
/// Its [`SensorOverlaps`] lists the circles its own layers meet, never another sensor; a
/// circle that left, was despawned or changed layers is an [`OverlapEnded`]. Since overlaps
/// are those of the state at the end of the step, a zone should be wider than a step's travel.
/// Spatial queries see sensors like any circle unless their
/// [`QueryFilter`](crate::game::query::QueryFilter) leaves them out (`excluding_sensors`).
/// `exact`'s engine sizes its cells only for circles that can meet another, so a wide sensor
/// does not coarsen them.
///
/// `tests/suite/sensors.rs` holds it against brute force under all five solvers: a world with
/// sensors moves every other circle bit for bit as one without them, and each step's lists
/// and messages are exactly the brute-force overlaps and their changes. `examples/sensor_zone.rs`
/// counts the balls through a goal zone and a picky zone on the gold balls' layer, and checks
/// the counts against the zones' lists and the balls' energy (unchanged: the zones took
/// nothing).
///
/// ```
/// use bevy::math::DVec2;
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// #[derive(Component)]
/// struct Goal;
///
/// fn spawn_goal(mut commands: Commands) {
///     commands.spawn((Goal, Radius(1.5), Position(DVec2::ZERO), Mass::IMMOVABLE, Sensor));
/// }
///
/// /// Runs after the step's sensors were looked at.
/// fn score(mut entered: MessageReader<OverlapStarted>, goals: Query<(), With<Goal>>) {
///     for m in entered.read().filter(|m| goals.contains(m.sensor)) {
///         info!("{} entered the goal", m.circle);
///     }
/// }
/// # fn add(app: &mut App) {
/// #     app.add_systems(Startup, spawn_goal)
/// #         .add_systems(FixedUpdate, score.after(CircleSystems::Sensors));
/// # }
/// ```
#[derive(Clone, Copy, Debug, Default)]
pub struct SensorPlugin;

impl Plugin for SensorPlugin {
    fn build(&self, app: &mut App) {
        app.register_type::<CollisionLayers>()
            .register_type::<Sensor>()
            .add_message::<OverlapStarted>()
            .add_message::<OverlapEnded>()
            .add_systems(
                FixedUpdate,
                detect_overlaps
                    .in_set(CircleSystems::Sensors)
                    .run_if(any_with_component::<Sensor>),
            );
    }
}

/// The sensor overlaps of one step: `(sensor, circle)` index pairs, sorted, with each pair
/// overlapping (centres nearer than the sum of the radii, as the solvers count an overlap, in
/// `arena`) and meeting by its layers. `sensors` and `circles` are `(centre, radius, layers)`;
/// `index` is reused from call to call.
pub fn sensor_overlaps(
    sensors: &[(DVec2, f64, CollisionLayers)],
    circles: &[(DVec2, f64, CollisionLayers)],
    arena: &Arena,
    index: &mut CircleIndex,
    pairs: &mut Vec<(u32, u32)>,
) {
    pairs.clear();
    let discs: Vec<(DVec2, f64)> = sensors.iter().map(|&(p, r, _)| (p, r)).collect();
    index.build(&discs, arena);
    for (k, &(p, r, layers)) in circles.iter().enumerate() {
        index.for_each_near(p, r, |s, offset, sensor_radius| {
            if offset.length() < r + sensor_radius && sensors[s as usize].2.meets(layers) {
                pairs.push((s, k as u32));
            }
        });
    }
    pairs.sort_unstable();
}

/// Buffers reused from step to step.
#[derive(Default)]
struct SensorScratch {
    sensors: Vec<(DVec2, f64, CollisionLayers)>,
    circles: Vec<(DVec2, f64, CollisionLayers)>,
    entities: Vec<Entity>,
    index: CircleIndex,
    pairs: Vec<(u32, u32)>,
    now: Vec<Entity>,
}

/// Gathers the sensors and the other circles, finds their overlaps with [`sensor_overlaps`],
/// and updates each sensor's [`SensorOverlaps`], writing a message per change.
#[allow(clippy::type_complexity)]
fn detect_overlaps(
    arena: Res<Arena>,
    mut sensors: Query<
        (
            Entity,
            &Position,
            &Radius,
            Option<&CollisionLayers>,
            &mut SensorOverlaps,
        ),
        With<Sensor>,
    >,
    circles: Query<(Entity, &Position, &Radius, Option<&CollisionLayers>), Without<Sensor>>,
    mut scratch: Local<SensorScratch>,
    mut messages: (MessageWriter<OverlapStarted>, MessageWriter<OverlapEnded>),
) {
    let scratch = &mut *scratch;
    let layers = |l: Option<&CollisionLayers>| l.copied().unwrap_or_default();
    scratch.sensors.clear();
    scratch
        .sensors
        .extend(sensors.iter().map(|(_, p, r, l, _)| (p.0, r.0, layers(l))));
    scratch.circles.clear();
    scratch.entities.clear();
    for (entity, p, r, l) in &circles {
        scratch.circles.push((p.0, r.0, layers(l)));
        scratch.entities.push(entity);
    }
    let (sensor_list, circle_list) = (&scratch.sensors, &scratch.circles);
    sensor_overlaps(
        sensor_list,
        circle_list,
        &arena,
        &mut scratch.index,
        &mut scratch.pairs,
    );
    let mut pairs = scratch.pairs.iter().peekable();
    for (s, (sensor, .., mut overlaps)) in sensors.iter_mut().enumerate() {
        scratch.now.clear();
        while let Some(&(_, k)) = pairs.next_if(|&&(t, _)| t as usize == s) {
            scratch.now.push(scratch.entities[k as usize]);
        }
        scratch.now.sort_unstable();
        if overlaps.0 == scratch.now {
            continue;
        }
        for change in changes(&overlaps.0, &scratch.now) {
            match change {
                Change::Started(circle) => {
                    messages.0.write(OverlapStarted { sensor, circle });
                }
                Change::Ended(circle) => {
                    messages.1.write(OverlapEnded { sensor, circle });
                }
            }
        }
        overlaps.0.clone_from(&scratch.now);
    }
}

/// A circle that came into or left a sensor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Change {
    Started(Entity),
    Ended(Entity),
}

/// What changed from `before` to `now` (both sorted), in entity order.
fn changes(before: &[Entity], now: &[Entity]) -> Vec<Change> {
    let (mut i, mut j) = (0, 0);
    let mut found = Vec::new();
    while i < before.len() || j < now.len() {
        match (before.get(i), now.get(j)) {
            (Some(a), Some(b)) if a == b => (i, j) = (i + 1, j + 1),
            (Some(&a), Some(&b)) if a < b => {
                found.push(Change::Ended(a));
                i += 1;
            }
            (Some(&a), None) => {
                found.push(Change::Ended(a));
                i += 1;
            }
            (_, Some(&b)) => {
                found.push(Change::Started(b));
                j += 1;
            }
            (None, None) => unreachable!("the loop ends first"),
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::arena::Boundary;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn changes_are_the_two_set_differences_in_order() {
        let e = |i: u32| Entity::from_raw_u32(i).unwrap();
        let sorted = |mut v: Vec<Entity>| {
            v.sort_unstable();
            v
        };
        let before = sorted(vec![e(1), e(3), e(5)]);
        let now = sorted(vec![e(2), e(3), e(6)]);
        let mut want = vec![
            Change::Ended(e(1)),
            Change::Started(e(2)),
            Change::Ended(e(5)),
            Change::Started(e(6)),
        ];
        let key = |c: &Change| match *c {
            Change::Started(e) | Change::Ended(e) => e,
        };
        want.sort_unstable_by_key(key);
        assert_eq!(changes(&before, &now), want);
        assert!(changes(&now, &now).is_empty());
    }

    #[test]
    fn overlaps_match_brute_force_with_layers_and_across_a_periodic_seam() {
        let arena = Arena::unit_square(Boundary::Periodic);
        let mut rng = ChaCha8Rng::seed_from_u64(12345);
        let mut body = |radii: std::ops::Range<f64>| {
            let p = DVec2::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
            let (member, meets) = (rng.random_range(0..2), rng.random_range(1..4));
            let layers = CollisionLayers::new(1 << member, meets);
            (p, rng.random_range(radii), layers)
        };
        let sensors: Vec<_> = (0..20).map(|_| body(0.02..0.12)).collect();
        let circles: Vec<_> = (0..500).map(|_| body(0.01..0.03)).collect();
        let mut pairs = Vec::new();
        sensor_overlaps(
            &sensors,
            &circles,
            &arena,
            &mut CircleIndex::default(),
            &mut pairs,
        );
        let mut brute = Vec::new();
        for (s, &(p, r, l)) in sensors.iter().enumerate() {
            for (k, &(q, t, m)) in circles.iter().enumerate() {
                if arena.offset(p, q).length() < r + t && l.meets(m) {
                    brute.push((s as u32, k as u32));
                }
            }
        }
        assert!(brute.len() > 20, "a test with few overlaps tests little");
        assert_eq!(pairs, brute);
    }
}
