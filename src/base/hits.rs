//! Collision messages and counters: a [`CircleHit`] per circle-circle impulse and a [`WallHit`]
//! per hit on an arena wall or a segment wall, written by whichever solver made the hit when the
//! scene opts in (`effects.hit_messages`), and the [`PairCollisions`] every solver counts.
//!
//! The kernels (the discrete contact pass, the wall reflection, the event engine) record hits
//! with circle indices into a [`HitLog`]; the solver's system turns indices into entities and
//! writes the messages. With messages off nothing is recorded, no system is added and nothing
//! is allocated: the kernels get no log.
//!
//! A game reads them like any Bevy message:
//!
//! ```
//! use bevy::prelude::*;
//! use moving_circles::base::hits::CircleHit;
//!
//! fn hard_hits(mut hits: MessageReader<CircleHit>) {
//!     for hit in hits.read().filter(|h| h.impulse > 5.0) {
//!         info!("{} hit {} at {} s into the step", hit.a, hit.b, hit.time);
//!     }
//! }
//! ```

use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;

/// One circle-circle collision: the impulse the solver applied to a pair.
///
/// `Id` is the circles' [`Entity`] in a message, and their index in the solver's arrays while a
/// kernel records it.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct CircleHit<Id: Send + Sync + 'static = Entity> {
    /// The first circle.
    pub a: Id,
    /// The second circle.
    pub b: Id,
    /// Where they touched (on `a`'s rim, in arena coordinates; on a periodic arena, beside `a`).
    pub point: DVec2,
    /// Unit normal from `a` towards `b`.
    pub normal: DVec2,
    /// Magnitude of the impulse along `normal` (`a` got `-impulse · normal`).
    pub impulse: f64,
    /// Speed at which they approached along the normal, before the impulse (positive).
    pub normal_speed: f64,
    /// When it happened, in seconds since the start of the fixed step: the exact event time
    /// under `swept`/`exact`, the end of the (sub)step under `discrete`/`substeps=N`.
    pub time: f64,
}

/// One of the arena's four walls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ArenaWall {
    /// `x = min.x`.
    Left,
    /// `x = max.x`.
    Right,
    /// `y = min.y`.
    Bottom,
    /// `y = max.y`.
    Top,
}

impl ArenaWall {
    /// The wall on `axis` (0 = x, 1 = y), at the high end if `high`.
    pub fn on_axis(axis: usize, high: bool) -> Self {
        match (axis, high) {
            (0, false) => Self::Left,
            (0, true) => Self::Right,
            (_, false) => Self::Bottom,
            (_, true) => Self::Top,
        }
    }

    /// Where a circle centred at `centre` touches this wall of `arena`, and the unit normal from
    /// the circle towards the wall.
    pub fn contact(self, centre: DVec2, arena: &Arena) -> (DVec2, DVec2) {
        let (axis, high) = match self {
            Self::Left => (0, false),
            Self::Right => (0, true),
            Self::Bottom => (1, false),
            Self::Top => (1, true),
        };
        let mut point = centre;
        point[axis] = if high {
            arena.max[axis]
        } else {
            arena.min[axis]
        };
        let mut normal = DVec2::ZERO;
        normal[axis] = if high { 1.0 } else { -1.0 };
        (point, normal)
    }
}

/// What a circle hit in a [`WallHit`]: one of the arena's walls or a segment wall inside it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Wall {
    /// An edge of the arena.
    Arena(ArenaWall),
    /// A segment wall, by its index in [`Segments`](crate::base::segment::Segments).
    Segment(u32),
}

/// One wall hit: a circle reflected off an arena wall or a segment wall.
#[derive(Message, Clone, Copy, Debug, PartialEq)]
pub struct WallHit<Id: Send + Sync + 'static = Entity> {
    /// The circle.
    pub circle: Id,
    /// The wall it hit.
    pub wall: Wall,
    /// Where it touched the wall.
    pub point: DVec2,
    /// Unit normal from the circle towards the wall.
    pub normal: DVec2,
    /// Momentum the wall took up, `m |Δv|` (infinite for an immovable circle).
    pub impulse: f64,
    /// Speed at which the circle approached the wall, before the hit (positive).
    pub normal_speed: f64,
    /// When it happened, in seconds since the start of the fixed step (as for [`CircleHit`]).
    pub time: f64,
    /// How many hits this message stands for: 1, except when one discrete step carried a
    /// circle across the arena and back several times (then `wall` is the last one it hit).
    pub count: u64,
}

/// Hits recorded by a kernel, with circle indices, in the order they happened.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HitLog {
    /// Circle-circle collisions.
    pub circles: Vec<CircleHit<u32>>,
    /// Wall hits.
    pub walls: Vec<WallHit<u32>>,
}

impl HitLog {
    /// Forgets every recorded hit (keeping the buffers).
    pub fn clear(&mut self) {
        self.circles.clear();
        self.walls.clear();
    }

    /// Writes the recorded circle-circle hits as messages, with `entity(i)` for circle `i` and
    /// `start` added to every time, and forgets them.
    pub fn send_circle_hits(
        &mut self,
        entity: impl Fn(u32) -> Entity,
        start: f64,
        messages: &mut MessageWriter<CircleHit>,
    ) {
        messages.write_batch(self.circles.drain(..).map(|h| CircleHit {
            a: entity(h.a),
            b: entity(h.b),
            time: start + h.time,
            point: h.point,
            normal: h.normal,
            impulse: h.impulse,
            normal_speed: h.normal_speed,
        }));
    }

    /// Writes the recorded wall hits as messages, as [`HitLog::send_circle_hits`] does.
    pub fn send_wall_hits(
        &mut self,
        entity: impl Fn(u32) -> Entity,
        start: f64,
        messages: &mut MessageWriter<WallHit>,
    ) {
        messages.write_batch(self.walls.drain(..).map(|h| WallHit {
            circle: entity(h.circle),
            time: start + h.time,
            wall: h.wall,
            point: h.point,
            normal: h.normal,
            impulse: h.impulse,
            normal_speed: h.normal_speed,
            count: h.count,
        }));
    }
}

/// Circle-circle collisions since the last (re)spawn, under any solver.
#[derive(
    Resource, Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize,
)]
pub struct PairCollisions {
    /// Impulses applied.
    pub count: u64,
    /// Collisional virial `Σ (r_a + r_b) · j` over those impulses (for the pressure).
    pub virial: f64,
    /// Kinetic energy that immovable (static or kinematic) circles gave the others: with
    /// elastic hits, the energy a kinematic paddle injected (a static peg gives none).
    pub immovable_work: f64,
    /// Momentum that immovable circles gave the others.
    pub immovable_impulse: bevy::math::DVec2,
}

impl PairCollisions {
    /// The collisions between `earlier` and these counters (all zero across a respawn, which
    /// restarts the counters).
    pub fn since(&self, earlier: &PairCollisions) -> PairCollisions {
        if self.count < earlier.count {
            return PairCollisions::default();
        }
        PairCollisions {
            count: self.count - earlier.count,
            virial: self.virial - earlier.virial,
            immovable_work: self.immovable_work - earlier.immovable_work,
            immovable_impulse: self.immovable_impulse - earlier.immovable_impulse,
        }
    }
}
