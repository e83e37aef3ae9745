//! The records the event engine keeps per circle (its motion, its pending event, its best pair),
//! a pair's relative motion, and the counts and errors it reports.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use crate::base::grid::NONE;

/// Counts of what the engine did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EventStats {
    /// Circle-circle collisions processed.
    pub pair_collisions: u64,
    /// Wall hits processed.
    pub wall_collisions: u64,
    /// Momentum taken up by the walls, `Σ m |Δv|`.
    pub wall_impulse: f64,
    /// `Σ (r_a + r_b) · j` over collisions.
    pub virial: f64,
    /// Kinetic energy immovable circles gave movable ones.
    pub immovable_work: f64,
    /// Momentum immovable circles gave movable ones.
    pub immovable_impulse: DVec2,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub(super) enum Kind {
    /// Nothing ahead (a resting circle alone).
    Idle,
    Pair,
    Wall {
        axis: u8,
    },
    Cell {
        axis: u8,
        up: bool,
    },
    /// A segment wall hit; the event's `partner` is the segment.
    Segment,
}

/// A circle's pending event (its time lives in the queue): `partner` is the other circle of a
/// pair event, the segment of a segment event, [`NONE`] otherwise.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Event {
    pub(super) kind: Kind,
    pub(super) partner: u32,
    pub(super) partner_count: u32,
}

/// What prediction reads for each circle, kept together for the cache.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct Motion {
    /// Position at time `t_at`.
    pub(super) pos: DVec2,
    pub(super) vel: DVec2,
    pub(super) t_at: f64,
    pub(super) radius: f64,
}

impl Motion {
    #[inline]
    pub(super) fn at(&self, t: f64) -> DVec2 {
        self.pos + self.vel * (t - self.t_at)
    }
}

/// What a pair's time is worked out in: now, and the arena's period when it wraps.
#[derive(Clone, Copy)]
pub(super) struct Frame {
    pub(super) now: f64,
    pub(super) period: Option<DVec2>,
}

/// A pair's relative motion from the later of its two reference times (where one of the two
/// is at its reference point: `at` adds nothing to it): that time, and the separation and
/// relative velocity then, the separation through the image `image` picks from where they are
/// now relative to each other, when the arena wraps (they may have flown far since).
#[inline(always)]
pub(super) fn relative(
    me: &Motion,
    other: &Motion,
    frame: Frame,
    image: impl Fn(DVec2) -> DVec2,
) -> (f64, DVec2, DVec2) {
    let since = me.t_at.max(other.t_at);
    let mut dp = other.at(since) - me.at(since);
    let dv = other.vel - me.vel;
    if let Some(period) = frame.period {
        dp -= period * image(dp + dv * (frame.now - since));
    }
    (since, dp, dv)
}

/// The soonest pair collision a circle's last look at its neighbours found.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(super) struct BestPair {
    pub(super) time: f64,
    pub(super) partner: u32,
    pub(super) partner_count: u32,
}

pub(super) const NO_PAIR: BestPair = BestPair {
    time: f64::INFINITY,
    partner: NONE,
    partner_count: 0,
};

/// Where a circle stands in coming to rest under gravity, carried from one engine to the next
/// (`swept` builds one every step something moves): whether it sleeps, and the place it has
/// stayed near while bouncing its least bounce, for how long.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Rest {
    /// Whether it sleeps.
    pub asleep: bool,
    /// Where it last moved to.
    pub anchor: DVec2,
    /// Seconds it has stayed near there.
    pub resting_for: f64,
}

/// Why [`EventEngine::advance_to`](super::EventEngine::advance_to) stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BudgetExhausted {
    /// Events processed before giving up.
    pub events: u64,
}
