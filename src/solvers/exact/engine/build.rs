//! Building an engine from circles: the cells laid out over the arena (and the few large
//! circles kept out of them), every circle put in its cell, and every circle's first event
//! predicted, in one go or asking between predictions whether to give up.

use bevy::math::DVec2;

use super::EventEngine;
use super::events::{Event, EventStats, Kind, Motion, NO_PAIR, Rest};
use super::queue::EventQueue;
use super::walls::{Layout, cell_width, walls_inside};
use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::collision_layers::CollisionLayers;
use crate::base::grid::{CellMembers, NONE};
use crate::base::segment::Segment;

/// Predictions between two looks at [`EventEngine::build_until`]'s stop request: a few
/// milliseconds of work.
pub const STOP_POLL_CIRCLES: usize = 16_384;

/// Entries of a table laid out between two looks at the stop request: a few megabytes, first
/// touched in some tens of milliseconds.
const STOP_POLL_ENTRIES: usize = 1 << 18;

/// `(0..n).map(entry)` collected, asking `stop` every [`STOP_POLL_ENTRIES`] entries: `None`
/// when it asked to give up. A table of millions takes a good part of a second to touch.
fn table_until<T>(
    n: usize,
    entry: impl Fn(usize) -> T,
    stop: &impl Fn() -> bool,
) -> Option<Vec<T>> {
    let mut table = Vec::with_capacity(n);
    for start in (0..n).step_by(STOP_POLL_ENTRIES) {
        if stop() {
            return None;
        }
        table.extend((start..n.min(start + STOP_POLL_ENTRIES)).map(&entry));
    }
    Some(table)
}

impl EventEngine {
    /// Builds the engine at time 0 and predicts every circle's first event. Circles must have
    /// finite state; with walls their centres must lie within `[min + r, max - r]` (a centre
    /// just outside by rounding is treated as touching the wall) and clear of the `segments`
    /// (ignored on a periodic arena).
    pub fn new(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitution: f64,
        wall_restitution: f64,
    ) -> Self {
        let width = cell_width(arena, circles, &[]);
        Self::with_cells(
            circles,
            arena,
            segments,
            (restitution, wall_restitution),
            width,
        )
    }

    /// [`EventEngine::new`] under `gravity`: movable circles fly parabolas, and each starts with
    /// its `Rest` in `rest` (one per circle, or none: all awake, not at rest). A circle whose bounce on a support
    /// (a wall, a segment wall, an immovable or sleeping circle) dies down falls asleep; a
    /// sleeping circle wakes when hit hard, or when [`EventEngine::set_motion`] moves it.
    pub fn falling(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitutions: (f64, f64),
        gravity: DVec2,
        rest: &[Rest],
    ) -> Self {
        let mut engine = Self::placed_falling(
            circles,
            arena,
            segments,
            restitutions,
            (gravity, rest),
            (&[], &|| false),
        )
        .expect("a build never asked to stop finishes");
        engine.predict_all();
        engine
    }

    /// [`EventEngine::new`], or [`EventEngine::falling`] under `gravity`, with each circle's
    /// `layers` (empty: every pair meets, [`EventEngine::set_layers`]), asking `stop` as its
    /// tables fill and every `STOP_POLL_CIRCLES` predictions whether to give up: `None` when
    /// it did. A build of
    /// millions of circles takes seconds, which a signal must not wait for.
    pub fn build_until(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitutions: (f64, f64),
        (gravity, rest): (Option<DVec2>, &[Rest]),
        layers: Vec<CollisionLayers>,
        stop: impl Fn() -> bool,
    ) -> Option<Self> {
        assert!(layers.is_empty() || layers.len() == circles.len());
        let mut engine = match gravity {
            Some(g) => Self::placed_falling(
                circles,
                arena,
                segments,
                restitutions,
                (g, rest),
                (&layers, &stop),
            ),
            None => Self::placed(
                circles,
                arena,
                segments,
                restitutions,
                cell_width(arena, circles, &layers),
                (&layers, &stop),
            ),
        }?;
        engine.layers = layers;
        engine.predict_all_until(stop).then_some(engine)
    }

    /// [`EventEngine::falling`] before any prediction: every circle in its cell (`None` when
    /// `stop` asked to give up).
    fn placed_falling(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitutions: (f64, f64),
        (gravity, rest): (DVec2, &[Rest]),
        (layers, stop): (&[CollisionLayers], &impl Fn() -> bool),
    ) -> Option<Self> {
        let width = cell_width(arena, circles, layers);
        let mut engine = Self::lay_out(
            circles,
            arena,
            segments,
            restitutions,
            (width, layers),
            stop,
        )?;
        engine.gravity = gravity;
        for i in 0..engine.len() {
            let at_rest = rest.get(i).copied().unwrap_or_default();
            engine.asleep[i] = at_rest.asleep;
            engine.anchor[i] = (at_rest.anchor, -at_rest.resting_for);
            if engine.asleep[i] {
                engine.motion[i].vel = DVec2::ZERO;
            }
            engine.falls[i] = engine.can_fall(i);
        }
        engine.relink_all();
        Some(engine)
    }

    /// [`EventEngine::new`] on cells at least `width` wide (and a largest diameter).
    pub(super) fn with_cells(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitutions: (f64, f64),
        width: f64,
    ) -> Self {
        let mut engine = Self::placed(
            circles,
            arena,
            segments,
            restitutions,
            width,
            (&[], &|| false),
        )
        .expect("a build never asked to stop finishes");
        engine.predict_all();
        engine
    }

    /// [`EventEngine::with_cells`] before any prediction: every circle in its cell (`None` when
    /// `stop` asked to give up).
    fn placed(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        restitutions: (f64, f64),
        width: f64,
        (layers, stop): (&[CollisionLayers], &impl Fn() -> bool),
    ) -> Option<Self> {
        let mut engine = Self::lay_out(
            circles,
            arena,
            segments,
            restitutions,
            (width, layers),
            stop,
        )?;
        engine.relink_all();
        Some(engine)
    }

    /// The engine's state for `circles` at time 0, before any circle is put in a cell or
    /// predicted, on cells sized for the circles that meet another under `layers`. Millions of
    /// circles take a second or more to lay out, mostly memory first touched: `stop` is asked
    /// as the tables fill (`None` when it asked to give up).
    fn lay_out(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        (restitution, wall_restitution): (f64, f64),
        (width, layers): (f64, &[CollisionLayers]),
        stop: &impl Fn() -> bool,
    ) -> Option<Self> {
        let go_on = || (!stop()).then_some(());
        let n = circles.len();
        let size = arena.size();
        let Layout {
            grid,
            segments,
            segment_cells,
            large,
            reach,
            images_wrap,
        } = walls_inside(arena, circles, segments, width, layers);
        let motion = table_until(
            n,
            |i| {
                let c = &circles[i];
                Motion {
                    pos: if arena.is_periodic() {
                        arena.wrap(c.position)
                    } else {
                        c.position
                    },
                    vel: c.velocity,
                    t_at: 0.0,
                    radius: c.radius,
                }
            },
            stop,
        )?;
        let inv_mass = table_until(n, |i| circles[i].inv_mass(), stop)?;
        let idle = Event {
            kind: Kind::Idle,
            partner: NONE,
            partner_count: 0,
        };
        let event = table_until(n, |_| idle, stop)?;
        let best_pair = table_until(n, |_| NO_PAIR, stop)?;
        let last_hit = table_until(n, |_| f64::NEG_INFINITY, stop)?;
        let anchor = table_until(n, |_| (DVec2::INFINITY, 0.0), stop)?;
        go_on()?;
        let queue = EventQueue::new(n);
        go_on()?;
        let cells = CellMembers::new(grid.len(), n);
        go_on()?;
        Some(Self {
            arena: *arena,
            period: size,
            restitution,
            wall_restitution,
            now: 0.0,
            motion,
            inv_mass,
            counter: vec![0; n],
            event,
            best_pair,
            queue,
            cells,
            grid,
            cell_x: vec![0; n],
            cell_y: vec![0; n],
            stats: EventStats::default(),
            segments,
            segment_cells,
            own_restitution: Vec::new(),
            layers: Vec::new(),
            pairs: true,
            hits: None,
            growth: 0.0,
            large,
            reach,
            images_wrap,
            gravity: DVec2::ZERO,
            falls: vec![false; n],
            asleep: vec![false; n],
            last_hit,
            quick_hits: vec![0; n],
            anchor,
            spins: None,
            #[cfg(target_arch = "x86_64")]
            batch: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use super::*;
    use crate::base::arena::Boundary;

    #[test]
    fn a_build_asked_to_stop_gives_up_and_one_never_asked_is_the_whole_build() {
        let arena = Arena::unit_square(Boundary::Walls);
        let circles: Vec<CircleState> = (0..40_000)
            .map(|i| {
                let (x, y) = ((i % 200) as f64 + 0.5, (i / 200) as f64 + 0.5);
                let v = DVec2::new((i * 7 % 5) as f64 - 2.0, (i * 3 % 7) as f64 - 3.0);
                CircleState::new(DVec2::new(x, y) / 200.0 - 0.5, v * 0.01, 0.001)
            })
            .collect();
        let (restitutions, fall) = ((1.0, 1.0), (None, &[][..]));
        let build = |stop: &dyn Fn() -> bool| {
            EventEngine::build_until(&circles, &arena, &[], restitutions, fall, Vec::new(), stop)
        };
        // A whole build looks between the layout's tables and every STOP_POLL_CIRCLES
        // predictions; told to stop at any of those looks, it gives up there.
        let asked = Cell::new(0);
        let whole = build(&|| {
            asked.set(asked.get() + 1);
            false
        });
        let looks = asked.get();
        let predicting = circles.len().div_ceil(STOP_POLL_CIRCLES);
        assert!(looks > predicting + 3, "{looks} looks");
        for stop_at in 1..=looks {
            let asked = Cell::new(0);
            let stopped = build(&|| {
                asked.set(asked.get() + 1);
                asked.get() == stop_at
            });
            assert!(stopped.is_none(), "went on at look {stop_at}");
            assert_eq!(asked.get(), stop_at);
        }
        let new = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
        assert_eq!(whole.map(|e| e.snapshot()), Some(new.snapshot()));
    }
}
