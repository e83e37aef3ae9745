//! The event-driven engine: circles fly in straight lines between events (parabolas under
//! gravity), and events (pair collisions, wall hits, segment wall hits, cell crossings) are
//! processed in time order.
//!
//! Each circle has exactly one pending event, its soonest, held in an indexed `EventQueue` (`queue.rs`).
//! A pair event remembers its partner's collision counter; if the partner has collided since,
//! the event is stale, and since nothing can have happened to the owner before it, the owner is
//! simply predicted again from that moment (`predict`).
//!
//! Positions are advanced lazily: circle `i` is at `pos + vel·(t - t_at)` (plus `½g(t - t_at)²`
//! if it falls), its reference point
//! moved only where its course changes, and every event time is worked out from reference
//! points, so the run does not depend on the cells. A `Grid` of cells sized to the density
//! (`walls::cell_width`) and at least one diameter of every circle in them wide, with
//! memberships kept up to date by cell-crossing events, keeps prediction local; a few circles far
//! wider than that stay out of the cells (`large`). A crossing changes no trajectory, so it
//! bumps no counter (events other circles hold with the crosser stay valid). Segment walls are
//! listed in the cells they pass within a largest radius of ([`SegmentCells`]), so a circle
//! looks only at its own cell's list, again after each crossing. In a compression the radii
//! grow as the circles fly (`growth`). Under gravity, circles at rest on a support sleep and
//! are woken by a hard hit (`rest`). Everything is f64.

#[cfg(target_arch = "x86_64")]
mod batch;
mod build;
mod events;
mod growth;
mod large;
mod motion;
mod pairs;
mod predict;
mod queue;
mod rest;
mod snapshot;
mod spin;
mod walls;

pub use build::STOP_POLL_CIRCLES;
pub use events::{BudgetExhausted, EventStats, Rest};
pub use snapshot::EngineSnapshot;
pub use spin::Roughness;

use events::{BestPair, Event, Kind, Motion};
use walls::{Layout, cell_width, walls_inside};

use bevy::math::DVec2;

use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::collision_layers::{CollisionLayers, can_meet, pair_meets};
use crate::base::grid::{CellMembers, Grid};
use crate::base::hits::HitLog;
use crate::base::segment::{Segment, SegmentCells};
use queue::EventQueue;

/// Events between two looks at [`EventEngine::advance_until_stopped`]'s stop request: about a
/// millisecond of events, so a stop is seen at once and asking costs nothing.
pub const STOP_POLL_EVENTS: u64 = 4096;

/// An event-driven simulation of circles.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::Arena;
/// use moving_circles::base::circle::CircleState;
/// use moving_circles::kernels::EventEngine;
///
/// let circles = [
///     CircleState::new(DVec2::new(-2.0, 0.0), DVec2::new(1.0, 0.0), 0.5),
///     CircleState::new(DVec2::new(2.0, 0.0), DVec2::new(-1.0, 0.0), 0.5),
/// ];
/// let mut engine = EventEngine::new(&circles, &Arena::default(), &[], 1.0, 1.0);
/// engine.advance_to(2.0, u64::MAX).unwrap();
/// assert_eq!(engine.stats().pair_collisions, 1); // they met at t = 1.5
/// assert_eq!(engine.velocity(0), DVec2::new(-1.0, 0.0));
/// ```
#[derive(Clone, Debug)]
pub struct EventEngine {
    arena: Arena,
    /// `arena.size()`, kept for the minimum image in the innermost loop.
    period: DVec2,
    restitution: f64,
    wall_restitution: f64,
    now: f64,
    motion: Vec<Motion>,
    inv_mass: Vec<f64>,
    /// Collisions (pair or wall) each circle has had: a pair event is valid while its
    /// partner's count is unchanged.
    counter: Vec<u32>,
    event: Vec<Event>,
    best_pair: Vec<BestPair>,
    queue: EventQueue,
    grid: Grid,
    cells: CellMembers,
    cell_x: Vec<u32>,
    cell_y: Vec<u32>,
    stats: EventStats,
    /// Segment walls (none on a periodic arena), and the cells they pass near.
    segments: Vec<Segment>,
    segment_cells: SegmentCells,
    /// Each circle's own restitution, or empty when all take the engine's.
    own_restitution: Vec<f64>,
    /// Each circle's layers, or empty when every pair meets: a pair that does not meet is
    /// never predicted.
    layers: Vec<CollisionLayers>,
    /// Whether circles collide at all: off, as under a scene without the collisions effect, no
    /// pair is predicted ([`EventEngine::set_pairs`]).
    pairs: bool,
    /// Hits since the last [`EventEngine::drain_hits`], when recording.
    hits: Option<HitLog>,
    /// How fast radii grow: circle `i`'s radius is `radius·(1 + growth·t)`. 0 but in a
    /// compression ([`EventEngine::growing`]).
    growth: f64,
    /// The few circles too large for the cells, in no cell list, and how many cells around its
    /// own each looks at.
    large: Vec<u32>,
    reach: Vec<u32>,
    /// Whether a pair may meet through an image it was not nearest in when predicted, so
    /// predictions look at every image in reach (`walls::images_wrap`).
    images_wrap: bool,
    /// The acceleration of every falling circle (zero without gravity).
    gravity: DVec2,
    /// Whether each circle falls: movable, awake, under gravity.
    falls: Vec<bool>,
    /// Whether each circle sleeps: at rest on a support, immovable until a hard hit wakes it.
    asleep: Vec<bool>,
    /// When each circle was last hit (under gravity, for the contact time).
    last_hit: Vec<f64>,
    /// How many hits in a row each circle took within its contact time of the one before.
    quick_hits: Vec<u32>,
    /// Where each circle last moved to, and when, while it bounces its least bounce.
    anchor: Vec<(DVec2, f64)>,
    /// Each circle's turning, when hits are rough (`spin`); none when smooth.
    spins: Option<spin::Spins>,
    /// Room for a scan's neighbours, kept from scan to scan (taken while one uses it).
    #[cfg(target_arch = "x86_64")]
    batch: Option<Box<batch::Batch>>,
}

impl EventEngine {
    /// Gives each circle its own restitution (one value per circle, in order; empty: all take
    /// the engine's). Pairs and wall hits then bounce with [`combine_restitution`](crate::kernels::combine_restitution).
    pub fn set_own_restitutions(&mut self, restitutions: Vec<f64>) {
        assert!(restitutions.is_empty() || restitutions.len() == self.len());
        self.own_restitution = restitutions;
    }

    /// Turns circle-circle collisions off (or on again) and predicts every circle again: off,
    /// circles pass through each other and still hit walls and segment walls. Not part of a
    /// snapshot: whoever restores one says it again ([`EventEngine::restore`]).
    pub fn set_pairs(&mut self, on: bool) {
        if self.pairs != on {
            self.pairs = on;
            self.predict_all();
        }
    }

    /// Gives each circle its layers (one per circle, in order; empty: every pair meets) and
    /// predicts every circle again, so no pair that does not meet has an event. To build an
    /// engine with layers from the start, see [`EventEngine::build_until`].
    pub fn set_layers(&mut self, layers: Vec<CollisionLayers>) {
        assert!(layers.is_empty() || layers.len() == self.len());
        let resized = (0..self.len()).any(|i| can_meet(&self.layers, i) != can_meet(&layers, i));
        self.layers = layers;
        // The cells are sized for the circles that meet another: a circle left out of the
        // sizing (a sensor, however wide) that now meets one needs cells sized for it. A
        // growing engine's cells are sized for every circle already.
        if resized && self.growth == 0.0 {
            self.lay_out_cells();
        }
        self.predict_all();
    }

    /// Lays the cells out again for the circles as they are now (same trajectories: the cells
    /// are bookkeeping), each listed in the cell it is in now.
    fn lay_out_cells(&mut self) {
        let circles: Vec<CircleState> = self
            .motion
            .iter()
            .map(|m| CircleState::new(m.pos, m.vel, m.radius))
            .collect();
        let width = cell_width(&self.arena, &circles, &self.layers);
        let Layout {
            grid,
            segment_cells,
            large,
            reach,
            images_wrap,
            ..
        } = walls_inside(&self.arena, &circles, &self.segments, width, &self.layers);
        (self.grid, self.segment_cells) = (grid, segment_cells);
        (self.large, self.reach, self.images_wrap) = (large, reach, images_wrap);
        self.cells = CellMembers::new(grid.len(), self.len());
        self.relink_all();
    }

    /// Whether the cells are sized for every circle: none meets nothing under the engine's
    /// layers (a sensor does, and is left out of the sizing).
    pub fn cells_sized_for_all(&self) -> bool {
        (0..self.len()).all(|i| can_meet(&self.layers, i))
    }

    /// Circle `i`'s layers ([`CollisionLayers::DEFAULT`] when the engine has none).
    pub fn layers(&self, i: usize) -> CollisionLayers {
        self.layers.get(i).copied().unwrap_or_default()
    }

    /// Whether circles `i` and `j` meet.
    #[inline]
    pub(super) fn meets(&self, i: usize, j: usize) -> bool {
        self.pairs && pair_meets(&self.layers, i, j)
    }

    /// Starts (or stops) recording every collision and wall hit, with its exact time, for
    /// [`EventEngine::drain_hits`].
    pub fn record_hits(&mut self, on: bool) {
        self.hits = on.then(HitLog::default);
    }

    /// The hits recorded so far, in time order, if recording (the caller drains them).
    pub fn drain_hits(&mut self) -> Option<&mut HitLog> {
        self.hits.as_mut()
    }

    /// Puts circle `i` at `position` with `velocity` now (something outside the engine moved
    /// it: a teleport, a kinematic circle steered by user code) and predicts it again. Events
    /// other circles hold with it become stale, as after a collision.
    pub fn set_motion(&mut self, i: usize, position: DVec2, velocity: DVec2) {
        let position = if self.arena.is_periodic() {
            self.arena.wrap(position)
        } else {
            position
        };
        self.asleep[i] = false;
        self.falls[i] = self.can_fall(i);
        self.motion[i].pos = position;
        self.motion[i].vel = velocity;
        self.motion[i].t_at = self.now;
        self.counter[i] += 1;
        let (x, y) = self.grid.cell_of(position);
        self.list_in(i, x, y);
        self.predict(i);
    }

    /// Current simulated time.
    pub fn now(&self) -> f64 {
        self.now
    }

    /// Number of circles.
    pub fn len(&self) -> usize {
        self.motion.len()
    }

    /// Whether there are no circles.
    pub fn is_empty(&self) -> bool {
        self.motion.is_empty()
    }

    /// What the engine has done so far.
    pub fn stats(&self) -> EventStats {
        self.stats
    }

    /// Position of circle `i` now (inside a periodic arena).
    #[inline]
    pub fn position(&self, i: usize) -> DVec2 {
        self.inside(self.pos_at(i, self.now))
    }

    /// Velocity of circle `i` now.
    #[inline]
    pub fn velocity(&self, i: usize) -> DVec2 {
        self.vel_at(i, self.now)
    }

    /// Whether nothing in the engine moves: no circle has a velocity, falls or turns, and radii
    /// do not grow (a pile asleep). No collision, wall hit or cell crossing can then come,
    /// however far it is advanced (only stale pair events, which move nothing).
    pub fn is_still(&self) -> bool {
        let turning = |i: usize| self.turn(i).is_some_and(|(spin, _)| spin != 0.0);
        self.growth == 0.0
            && (0..self.len())
                .all(|i| !self.falls[i] && self.motion[i].vel == DVec2::ZERO && !turning(i))
    }

    /// Whether circle `i` sleeps.
    pub fn is_asleep(&self, i: usize) -> bool {
        self.asleep[i]
    }

    /// Circle `i`'s `Rest` now: what a fresh engine needs to go on resting it.
    pub fn rest(&self, i: usize) -> Rest {
        let (anchor, since) = self.anchor[i];
        Rest {
            asleep: self.asleep[i],
            anchor,
            resting_for: (self.now - since).max(0.0),
        }
    }

    /// What circle `i` was built with: radius, inverse mass and the restitution it bounces
    /// off other circles with (its own, or the engine's).
    pub fn body(&self, i: usize) -> (f64, f64, f64) {
        let restitution = self.own_restitution.get(i).copied();
        (
            self.motion[i].radius,
            self.inv_mass[i],
            restitution.unwrap_or(self.restitution),
        )
    }

    /// Processes every event up to time `t_end` and moves the clock there. Stops early (with the
    /// clock at the last processed event) after `max_events` events.
    pub fn advance_to(&mut self, t_end: f64, max_events: u64) -> Result<u64, BudgetExhausted> {
        self.advance_until_stopped(t_end, max_events, || false)
    }

    /// [`EventEngine::advance_to`], also stopping early (as if the budget ran out) when `stop`
    /// says so; it is asked every `STOP_POLL_EVENTS` events.
    pub fn advance_until_stopped(
        &mut self,
        t_end: f64,
        max_events: u64,
        stop: impl Fn() -> bool,
    ) -> Result<u64, BudgetExhausted> {
        let mut processed = 0;
        while let Some((i, time)) = self.queue.first() {
            if time > t_end {
                break;
            }
            let event = self.event[i];
            if event.kind == Kind::Pair
                && self.counter[event.partner as usize] != event.partner_count
            {
                // The partner moved on; the owner's path is unchanged up to now: predict again.
                self.now = time.max(self.now);
                self.predict(i);
                continue;
            }
            if processed == max_events
                || (processed % STOP_POLL_EVENTS == STOP_POLL_EVENTS - 1 && stop())
            {
                return Err(BudgetExhausted { events: processed });
            }
            processed += 1;
            self.now = time.max(self.now);
            match event.kind {
                Kind::Pair => self.collide(i, event.partner as usize),
                Kind::Wall { axis } => self.hit_wall(i, axis as usize),
                Kind::Cell { axis, up } => self.cross_cell(i, axis as usize, up),
                Kind::Segment => self.hit_segment(i, event.partner as usize),
                Kind::Idle => unreachable!("idle circles wait at +∞"),
            }
        }
        self.now = t_end;
        Ok(processed)
    }

    fn cell_index(&self, i: usize) -> usize {
        self.grid
            .index(self.cell_x[i] as usize, self.cell_y[i] as usize)
    }

    /// The circles listed in the cells around circle `i`'s (its own among them), then the
    /// large circles, which no cell lists: every circle near enough to touch `i`.
    fn near(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let (cells, len) = self
            .grid
            .block(self.cell_x[i] as usize, self.cell_y[i] as usize);
        let listed = (0..len).flat_map(move |k| self.cells.members(cells[k]));
        listed.chain(self.large.iter().map(|&j| j as usize))
    }

    /// Puts every circle in the cell its position now lies in (large circles in none, but each
    /// still knows its cell). Where every reference time is now (a build, a drift) that is the
    /// reference point itself.
    fn relink_all(&mut self) {
        self.cells.clear();
        for i in 0..self.len() {
            let (x, y) = self.grid.cell_of(self.inside(self.pos_at(i, self.now)));
            self.cell_x[i] = x as u32;
            self.cell_y[i] = y as u32;
            if self.large_reach(i).is_none() {
                self.cells.insert(i, self.grid.index(x, y));
            }
        }
    }

    /// Lists circle `i` in the cell its position lies in, if that is not the one it is listed
    /// in: after a move that is not motion (a centre put back inside the walls).
    fn relist(&mut self, i: usize) {
        let (x, y) = self.grid.cell_of(self.motion[i].pos);
        if (x as u32, y as u32) != (self.cell_x[i], self.cell_y[i]) {
            self.list_in(i, x, y);
        }
    }

    /// Takes circle `i` out of the cell it is listed in and lists it in cell `(x, y)` (a large
    /// circle is in no cell's list, but knows its cell).
    fn list_in(&mut self, i: usize, x: usize, y: usize) {
        let listed = self.large_reach(i).is_none();
        if listed {
            self.cells.remove(i, self.cell_index(i));
        }
        (self.cell_x[i], self.cell_y[i]) = (x as u32, y as u32);
        if listed {
            self.cells.insert(i, self.grid.index(x, y));
        }
    }

    /// Moves circle `i` into the next cell along `axis` (past a periodic edge, the first cell
    /// on the other side). Its course is unchanged, so its motion is left as it is.
    fn cross_cell(&mut self, i: usize, axis: usize, up: bool) {
        let listed = self.large_reach(i).is_none();
        if listed {
            self.cells.remove(i, self.cell_index(i));
        }
        let (count, cell) = if axis == 0 {
            (self.grid.cols as u32, &mut self.cell_x[i])
        } else {
            (self.grid.rows as u32, &mut self.cell_y[i])
        };
        // The next cell, wrapping past a periodic edge (no division: a crossing is frequent).
        *cell = match (up, *cell) {
            (true, c) if c + 1 == count => 0,
            (true, c) => c + 1,
            (false, 0) => count - 1,
            (false, c) => c - 1,
        };
        if listed {
            self.cells.insert(i, self.cell_index(i));
        }
        self.predict_after_crossing(i, axis, up);
    }
}
