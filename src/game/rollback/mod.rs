//! Rollback in memory: [`CirclesSnapshot`], everything the next fixed step depends on, saved
//! and put back without files, for a game that rolls back (by hand, or through a rollback
//! library) and for anything that must step one world twice from the same state.
//!
//! What a snapshot holds: each circle's motion, spin and rest, in serial order
//! ([`CircleSerial`]) as 8-byte words with zero values left out; the `soft` solver's contacts
//! and impulses (its warm start); the engine `swept` and `exact` keep; the step, drop, sleep
//! and hit counters. What it does not hold, because only your code changes it: the circles'
//! radius, mass and tint and what they have of their own (restitution, friction, moment of
//! inertia, layers, sensors), the configuration and the scene. A circle keeps its serial
//! whatever its entity, so a snapshot goes back into a world whose circles were despawned and
//! spawned again with their serials (new entity ids), as a rollback library does.
//!
//! Putting a snapshot back writes past Bevy's change detection: to the solvers and to sleep, a
//! circle put back was not moved from outside (which would wake it, or make `exact` build a
//! fresh engine, and a run that rolls back would step to other bits than one that does not).

mod circles;
#[cfg(feature = "ggrs")]
pub mod ggrs;

use std::hash::{BuildHasher, Hasher};

use bevy::ecs::component::Mutable;
use bevy::platform::hash::FixedHasher;
use bevy::prelude::*;

use crate::base::components::CircleSerial;
use crate::base::hits::PairCollisions;
use crate::game::spawn::Dropped;
use crate::solvers::exact::EngineState;
use crate::solvers::soft::{ContactCache, SoftState, SoftStats};
use crate::step::boundary::WallCollisions;
use crate::step::schedule::StepTotals;
use crate::step::sleep::Sleeping;
use circles::{
    SnapshotQueries, forget_changes, long_ago, pop_serial, push_circle, push_serial, put_back,
};

/// The state of every circle and of the solvers between two fixed steps: what
/// [`CirclesSnapshot::restore`] puts back so that the world steps on to the same bits as from
/// [`CirclesSnapshot::save`]. Saving into a snapshot that held one before reuses its memory.
///
/// ```
/// # use bevy::prelude::*;
/// # use moving_circles::prelude::*;
/// use moving_circles::game::rollback::CirclesSnapshot;
///
/// fn step_twice(app: &mut App) {
///     let mut snapshot = CirclesSnapshot::default();
///     snapshot.save(app.world_mut());
///     app.update();
///     let once = CirclesSnapshot::taken(app.world_mut()).state_hash();
///     snapshot.restore(app.world_mut()).expect("the same circles");
///     app.update();
///     assert_eq!(CirclesSnapshot::taken(app.world_mut()).state_hash(), once);
/// }
/// ```
#[derive(Default)]
pub struct CirclesSnapshot {
    /// Each circle's serial, less the one before it (LEB128).
    serials: Vec<u8>,
    /// Per circle, which words follow its position ([`Words`]).
    flags: Vec<u8>,
    words: Vec<u64>,
    counters: Counters,
    contacts: ContactCache,
    engine: EngineState,
}

impl Clone for CirclesSnapshot {
    fn clone(&self) -> Self {
        let mut copy = Self::default();
        copy.clone_from(self);
        copy
    }

    /// Copies `source` into the memory this snapshot holds already.
    fn clone_from(&mut self, source: &Self) {
        self.serials.clone_from(&source.serials);
        self.flags.clone_from(&source.flags);
        self.words.clone_from(&source.words);
        self.counters = source.counters;
        self.contacts.clone_from(&source.contacts);
        self.engine.clone_from(&source.engine);
    }
}

/// The counters a step reads or adds to.
#[derive(Clone, Copy, Default, PartialEq)]
struct Counters {
    steps: StepTotals,
    pairs: PairCollisions,
    walls: WallCollisions,
    sleeping: Sleeping,
    dropped: Dropped,
    soft_last: SoftStats,
}

/// Why a snapshot cannot go back into a world.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RollbackError {
    /// A circle of the snapshot is not in the world.
    #[error(
        "the circle of serial {0} in the snapshot is not in the world (spawn it again with its \
         CircleSerial before restoring)"
    )]
    Missing(u64),
}

impl CirclesSnapshot {
    /// A snapshot of `world` now.
    pub fn taken(world: &mut World) -> Self {
        let mut snapshot = Self::default();
        snapshot.save(world);
        snapshot
    }

    /// Saves `world`'s circles and solver state into this snapshot, between two fixed steps.
    pub fn save(&mut self, world: &mut World) {
        world.init_resource::<SnapshotQueries>();
        world.resource_scope(|world, mut queries: Mut<SnapshotQueries>| {
            self.serials.clear();
            self.flags.clear();
            self.words.clear();
            let mut last = 0;
            let queries = &mut *queries;
            let mut keep = |serial: CircleSerial, motion: (_, _, _, _, _)| {
                push_serial(&mut self.serials, serial.0 - last);
                last = serial.0;
                push_circle((&mut self.flags, &mut self.words), motion);
            };
            if queries.in_serial_order(world) {
                let circles = queries.serials.iter(world).zip(queries.read.iter(world));
                circles.for_each(|((_, &serial), motion)| keep(serial, motion));
            } else {
                queries.order(world);
                for &(serial, entity) in &queries.ordered {
                    if let Ok(motion) = queries.read.get(world, entity) {
                        keep(serial, motion);
                    }
                }
            }
        });
        self.counters = Counters {
            steps: kept(world),
            pairs: kept(world),
            walls: kept(world),
            sleeping: kept(world),
            dropped: kept(world),
            soft_last: world
                .get_resource::<SoftState>()
                .map_or_else(Default::default, |s| s.last),
        };
        if let Some(soft) = world.get_resource::<SoftState>() {
            self.contacts.copy_kept_from(soft.contacts());
        }
        if let Some(engine) = world.get_resource::<EngineState>() {
            self.engine.clone_from(engine);
        }
    }

    /// Puts this snapshot back into `world`: every circle of it (found by serial, whatever its
    /// entity now) where it was, with its motion, spin and rest; the solvers' kept state and
    /// the counters as they were. Circles the world has and the snapshot does not (spawned
    /// since it was saved: a drop) are despawned. The world's circles must be the snapshot's:
    /// one it lacks is an error, and nothing is changed.
    pub fn restore(&self, world: &mut World) -> Result<(), RollbackError> {
        world.init_resource::<SnapshotQueries>();
        world.resource_scope(|world, mut queries: Mut<SnapshotQueries>| {
            // Most often the world's circles are the snapshot's, in the order a query yields
            // them: then they are written as it yields them.
            let same = queries.yields(world, self.serial_values());
            if same {
                let SnapshotQueries {
                    serials,
                    entities,
                    extra,
                    ..
                } = &mut *queries;
                entities.clear();
                entities.extend(serials.iter(world).map(|(e, _)| e));
                extra.clear();
            } else {
                queries.order(world);
                self.match_circles(&mut queries)?;
            }
            let SnapshotQueries {
                write,
                parts,
                entities,
                ..
            } = &mut *queries;
            let (mut flags, mut words) = (self.flags.iter(), self.words.iter().copied());
            let old = long_ago(world);
            if same {
                // The world's circles are the snapshot's, in the order a query yields them.
                write
                    .iter_mut(world)
                    .zip(&mut flags)
                    .for_each(|(motion, &f)| {
                        put_back((f, old), &mut words, motion);
                    });
                parts
                    .iter_mut(world)
                    .for_each(|circle| forget_changes(circle, old));
            } else {
                for &entity in entities.iter() {
                    let (Some(&f), Ok(motion)) = (flags.next(), write.get_mut(world, entity))
                    else {
                        continue;
                    };
                    put_back((f, old), &mut words, motion);
                    if let Ok(circle) = parts.get_mut(world, entity) {
                        forget_changes(circle, old);
                    }
                }
            }
            for &entity in &queries.extra {
                world.despawn(entity);
            }
            if let Some(mut engine) = world.get_resource_mut::<EngineState>() {
                engine.clone_from(&self.engine);
                engine.rekey(&queries.entities);
            }
            Ok(())
        })?;
        let Counters {
            steps,
            pairs,
            walls,
            sleeping,
            dropped,
            soft_last,
        } = self.counters;
        put(world, steps);
        put(world, pairs);
        put(world, walls);
        put(world, sleeping);
        put(world, dropped);
        if let Some(mut soft) = world.get_resource_mut::<SoftState>() {
            soft.contacts_mut().copy_kept_from(&self.contacts);
            soft.last = soft_last;
        }
        Ok(())
    }

    /// Pairs the snapshot's circles with the world's (`queries.ordered`) by serial, into
    /// `queries.entities` (the snapshot's circles' entities, in its order) and `queries.extra`
    /// (the world's circles the snapshot lacks).
    fn match_circles(&self, queries: &mut SnapshotQueries) -> Result<(), RollbackError> {
        queries.entities.clear();
        queries.extra.clear();
        let mut world = queries.ordered.iter().peekable();
        for serial in self.serial_values() {
            while let Some(&&(s, e)) = world.peek()
                && s.0 < serial
            {
                queries.extra.push(e);
                world.next();
            }
            match world.next() {
                Some(&(s, e)) if s.0 == serial => queries.entities.push(e),
                _ => return Err(RollbackError::Missing(serial)),
            }
        }
        queries.extra.extend(world.map(|&(_, e)| e));
        Ok(())
    }

    /// The snapshot's serials, in its order.
    fn serial_values(&self) -> impl Iterator<Item = u64> + '_ {
        let (mut bytes, mut serial) = (&self.serials[..], 0u64);
        std::iter::from_fn(move || {
            (!bytes.is_empty()).then(|| {
                serial += pop_serial(&mut bytes);
                serial
            })
        })
    }

    /// Circles in the snapshot.
    pub fn len(&self) -> usize {
        self.flags.len()
    }

    /// Whether the snapshot holds no circle.
    pub fn is_empty(&self) -> bool {
        self.flags.is_empty()
    }

    /// Bytes of what it holds for its circles, and for the `soft` solver's contacts.
    pub fn bytes(&self) -> (usize, usize) {
        let circles = self.serials.len() + self.flags.len() + size_of_val(&self.words[..]);
        (circles, self.contacts.kept_bytes())
    }

    /// A checksum of the simulation's state (every circle's motion, spin and rest by serial
    /// order, and the step, sleep and drop counters): equal in two worlds that step on the
    /// same, on any machine. What a rollback library compares between peers.
    pub fn state_hash(&self) -> u64 {
        let mut hasher = FixedHasher.build_hasher();
        hasher.write_usize(self.flags.len());
        hasher.write(&self.flags);
        for &word in &self.words {
            hasher.write_u64(word);
        }
        let Counters {
            steps,
            sleeping,
            dropped,
            ..
        } = self.counters;
        hasher.write_u64(steps.steps);
        hasher.write_u64(steps.sim_seconds.to_bits());
        hasher.write_usize(sleeping.count);
        hasher.write_usize(dropped.count);
        hasher.finish()
    }
}

/// The world's `R`, or its default where a plugin left out has none.
fn kept<R: Resource + Copy + Default>(world: &World) -> R {
    world.get_resource::<R>().copied().unwrap_or_default()
}

/// Puts `value` back as the world's `R`, if it has one.
fn put<R: Resource<Mutability = Mutable> + Copy + PartialEq>(world: &mut World, value: R) {
    if let Some(mut r) = world.get_resource_mut::<R>()
        && *r != value
    {
        *r = value;
    }
}
