//! How a snapshot holds each circle: its serial as the difference from the one before
//! (LEB128), a byte of flags saying which of its words follow its position (velocity, spin,
//! rotation, rest; asleep), the words themselves (f64 bits); and how a restore writes them back
//! so that the circle looks unchanged to every system.

use bevy::ecs::change_detection::{MAX_CHANGE_AGE, Tick};
use bevy::ecs::query::{QueryItem, QueryState};
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::collision_layers::{CollisionLayers, Sensor};
use crate::base::components::{
    AngularVelocity, CircleSerial, Inertia, Mass, Position, Radius, Restitution, Rotation, Sleep,
    Velocity,
};

/// The words a circle has past its position, one bit each in its flags.
pub(super) struct Words;

impl Words {
    pub(super) const VELOCITY: u8 = 1;
    pub(super) const SPIN: u8 = 2;
    pub(super) const ROTATION: u8 = 4;
    pub(super) const REST: u8 = 8;
    pub(super) const ASLEEP: u8 = 16;
}

/// The circles a snapshot holds: every entity the solvers step (a circle may lack its spin
/// or angle: it does not turn). Every query of a save or restore has this filter, so they
/// yield the same circles in the same order.
pub(super) type Circles = (With<Radius>, With<Position>, With<Velocity>, With<Sleep>);

/// A circle's parts a snapshot holds.
pub(super) type Motion = (
    &'static Position,
    &'static Velocity,
    Option<&'static AngularVelocity>,
    Option<&'static Rotation>,
    &'static Sleep,
);

/// The same, to put back.
pub(super) type MotionMut = (
    &'static mut Position,
    &'static mut Velocity,
    Option<&'static mut AngularVelocity>,
    Option<&'static mut Rotation>,
    &'static mut Sleep,
);

/// What else a circle is made of, whose changes a restore forgets.
pub(super) type Parts = (
    &'static mut Radius,
    &'static mut Mass,
    Option<&'static mut Restitution>,
    Option<&'static mut Inertia>,
    Option<&'static mut CollisionLayers>,
    Option<&'static mut Sensor>,
);

/// The queries saving and restoring use, and the circles in serial order, kept in the world
/// so that a save or restore after the first allocates nothing.
#[derive(Resource)]
pub(super) struct SnapshotQueries {
    pub(super) serials: QueryState<(Entity, &'static CircleSerial), Circles>,
    pub(super) read: QueryState<Motion, Circles>,
    pub(super) write: QueryState<MotionMut, Circles>,
    pub(super) parts: QueryState<Parts, Circles>,
    pub(super) ordered: Vec<(CircleSerial, Entity)>,
    pub(super) extra: Vec<Entity>,
    pub(super) entities: Vec<Entity>,
}

impl FromWorld for SnapshotQueries {
    fn from_world(world: &mut World) -> Self {
        Self {
            serials: world.query_filtered(),
            read: world.query_filtered(),
            write: world.query_filtered(),
            parts: world.query_filtered(),
            ordered: Vec::new(),
            extra: Vec::new(),
            entities: Vec::new(),
        }
    }
}

impl SnapshotQueries {
    /// Whether a query yields the world's circles in serial order (one look at each serial;
    /// saving then reads them as the query yields them).
    pub(super) fn in_serial_order(&mut self, world: &World) -> bool {
        let serials = self.serials.iter(world).map(|(_, &s)| s);
        serials.is_sorted_by(|a, b| a < b)
    }

    /// Whether a query yields the world's circles with exactly the serials `serials` yields,
    /// in that order (restoring then writes them as the query yields them).
    pub(super) fn yields(&mut self, world: &World, serials: impl Iterator<Item = u64>) -> bool {
        self.serials.iter(world).map(|(_, s)| s.0).eq(serials)
    }

    /// Lists the world's circles in serial order.
    pub(super) fn order(&mut self, world: &World) {
        self.ordered.clear();
        self.ordered
            .extend(self.serials.iter(world).map(|(e, &serial)| (serial, e)));
        if !self.ordered.is_sorted_by_key(|&(s, _)| s) {
            self.ordered.sort_unstable();
        }
    }
}

/// Appends one circle's flags and words.
pub(super) fn push_circle(
    (flags_of, words): (&mut Vec<u8>, &mut Vec<u64>),
    (p, v, w, a, rest): QueryItem<'_, '_, Motion>,
) {
    let mut flags = 0;
    words.extend([p.0.x.to_bits(), p.0.y.to_bits()]);
    if v.0.x.to_bits() != 0 || v.0.y.to_bits() != 0 {
        flags |= Words::VELOCITY;
        words.extend([v.0.x.to_bits(), v.0.y.to_bits()]);
    }
    let (w, a) = (w.map_or(0.0, |w| w.0), a.map_or(0.0, |a| a.0));
    for (value, flag) in [(w, Words::SPIN), (a, Words::ROTATION)] {
        if value.to_bits() != 0 {
            flags |= flag;
            words.push(value.to_bits());
        }
    }
    let anchor = rest.anchor;
    if [anchor.x, anchor.y, rest.slow_for]
        .iter()
        .any(|x| x.to_bits() != 0)
    {
        flags |= Words::REST;
        words.extend([
            anchor.x.to_bits(),
            anchor.y.to_bits(),
            rest.slow_for.to_bits(),
        ]);
    }
    if rest.asleep {
        flags |= Words::ASLEEP;
    }
    flags_of.push(flags);
}

/// Writes one circle's words back, past change detection, and makes them look unchanged.
pub(super) fn put_back(
    (flags, long_ago): (u8, Tick),
    words: &mut impl Iterator<Item = u64>,
    (mut p, mut v, mut w, mut a, mut rest): QueryItem<'_, '_, MotionMut>,
) {
    let mut next = |present: bool| {
        if present {
            f64::from_bits(words.next().unwrap_or(0))
        } else {
            0.0
        }
    };
    let has = |flag: u8| flags & flag != 0;
    let position = DVec2::new(next(true), next(true));
    let velocity = DVec2::new(next(has(Words::VELOCITY)), next(has(Words::VELOCITY)));
    let (spin, angle) = (next(has(Words::SPIN)), next(has(Words::ROTATION)));
    let anchor = DVec2::new(next(has(Words::REST)), next(has(Words::REST)));
    let sleep = Sleep {
        anchor,
        slow_for: next(has(Words::REST)),
        asleep: has(Words::ASLEEP),
    };
    p.bypass_change_detection().0 = position;
    v.bypass_change_detection().0 = velocity;
    if let Some(w) = w.as_mut() {
        w.bypass_change_detection().0 = spin;
        w.set_last_changed(long_ago);
    }
    if let Some(a) = a.as_mut() {
        a.bypass_change_detection().0 = angle;
        a.set_last_changed(long_ago);
    }
    *rest.bypass_change_detection() = sleep;
    p.set_last_changed(long_ago);
    v.set_last_changed(long_ago);
    rest.set_last_changed(long_ago);
}

/// A change tick older than any system's last run: a component given it looks unchanged to
/// every system, as it was when the snapshot was saved (what a step reads to tell a circle
/// your code moved, which wakes it, or a part it changed, which makes `exact` rebuild).
pub(super) fn long_ago(world: &World) -> Tick {
    Tick::new(world.read_change_tick().get().wrapping_sub(MAX_CHANGE_AGE))
}

/// Makes what else a circle is made of look unchanged (see [`long_ago`]): a rollback library
/// that spawned the circle again, or put back its parts, marked them changed.
pub(super) fn forget_changes(
    (mut radius, mut mass, restitution, inertia, layers, sensor): QueryItem<'_, '_, Parts>,
    long_ago: Tick,
) {
    radius.set_last_changed(long_ago);
    mass.set_last_changed(long_ago);
    if let Some(mut part) = restitution {
        part.set_last_changed(long_ago);
    }
    if let Some(mut part) = inertia {
        part.set_last_changed(long_ago);
    }
    if let Some(mut part) = layers {
        part.set_last_changed(long_ago);
    }
    if let Some(mut part) = sensor {
        part.set_last_changed(long_ago);
    }
}

/// Appends `delta` to `bytes`, seven bits a byte, low first (LEB128).
pub(super) fn push_serial(bytes: &mut Vec<u8>, mut delta: u64) {
    while delta >= 0x80 {
        bytes.push((delta as u8 & 0x7f) | 0x80);
        delta >>= 7;
    }
    bytes.push(delta as u8);
}

/// Takes one value written by [`push_serial`] off the front of `bytes`.
pub(super) fn pop_serial(bytes: &mut &[u8]) -> u64 {
    let (mut value, mut shift) = (0u64, 0);
    while let Some((&byte, rest)) = bytes.split_first() {
        *bytes = rest;
        value |= u64::from(byte & 0x7f) << shift;
        shift += 7;
        if byte & 0x80 == 0 {
            break;
        }
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serial_differences_come_back_as_written() {
        let deltas = [0, 1, 127, 128, 300, 1 << 40, u64::MAX];
        let mut bytes = Vec::new();
        deltas.iter().for_each(|&d| push_serial(&mut bytes, d));
        assert_eq!(bytes.len(), 1 + 1 + 1 + 2 + 2 + 6 + 10);
        let mut rest = &bytes[..];
        let back: Vec<u64> = deltas.iter().map(|_| pop_serial(&mut rest)).collect();
        assert_eq!(back, deltas);
        assert!(rest.is_empty());
    }
}
