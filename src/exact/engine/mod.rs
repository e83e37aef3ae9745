//! The event-driven engine: circles fly in straight lines between events, and events (pair
//! collisions, wall hits, segment wall hits, cell crossings) are processed in time order.
//!
//! Each circle has exactly one pending event, its soonest, held in an indexed [`EventQueue`].
//! A pair event remembers its partner's collision counter; if the partner has collided since,
//! the event is stale, and since nothing can have happened to the owner before it, the owner is
//! simply predicted again from that moment (`predict`).
//!
//! Positions are advanced lazily: circle `i` is at `pos + vel·(t - t_at)`, its reference point
//! moved only where its course changes, and every event time is worked out from reference
//! points, so the run does not depend on the cells. A [`Grid`] of cells sized to the density
//! (`walls::cell_width`) and at least one diameter of every circle in them wide, with
//! memberships kept up to date by cell-crossing events, keeps prediction local; a few circles far
//! wider than that stay out of the cells (`large`). A crossing changes no trajectory, so it
//! bumps no counter (events other circles hold with the crosser stay valid). Segment walls are
//! listed in the cells they pass within a largest radius of ([`SegmentCells`]), so a circle
//! looks only at its own cell's list, again after each crossing. In a compression the radii
//! grow as the circles fly (`growth`). Everything is f64.

mod events;
mod growth;
mod large;
mod predict;
mod snapshot;
mod walls;

pub use events::{BudgetExhausted, EventStats};
pub use snapshot::EngineSnapshot;

use events::{BestPair, Event, Kind, Motion, NO_PAIR};
use walls::{Layout, cell_width, walls_inside};

use bevy::math::DVec2;

use super::queue::EventQueue;
use crate::arena::{Arena, minimum_image};
use crate::boundary::reflect_off_walls;
use crate::circle::CircleState;
use crate::collide::contact::{
    apply_impulse, combine_restitution, contact_normal, work_by_immovable,
};
use crate::grid::{CellMembers, Grid, NONE};
use crate::hits::{CircleHit, HitLog};
use crate::segment::{Segment, SegmentCells};

/// An event-driven simulation of circles.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::arena::Arena;
/// use moving_circles::circle::CircleState;
/// use moving_circles::exact::engine::EventEngine;
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
    /// Hits since the last [`EventEngine::drain_hits`], when recording.
    hits: Option<HitLog>,
    /// How fast radii grow: circle `i`'s radius is `radius·(1 + growth·t)`. 0 but in a
    /// compression ([`EventEngine::growing`]).
    growth: f64,
    /// The few circles too large for the cells, in no cell list, and how many cells around its
    /// own each looks at.
    large: Vec<u32>,
    reach: Vec<u32>,
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
        let width = cell_width(arena, circles);
        Self::with_cells(
            circles,
            arena,
            segments,
            (restitution, wall_restitution),
            width,
        )
    }

    /// [`EventEngine::new`] on cells at least `width` wide (and a largest diameter).
    fn with_cells(
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        (restitution, wall_restitution): (f64, f64),
        width: f64,
    ) -> Self {
        let n = circles.len();
        let size = arena.size();
        let Layout {
            grid,
            segments,
            segment_cells,
            large,
            reach,
        } = walls_inside(arena, circles, segments, width);
        let mut engine = Self {
            arena: *arena,
            period: size,
            restitution,
            wall_restitution,
            now: 0.0,
            motion: circles
                .iter()
                .map(|c| Motion {
                    pos: if arena.is_periodic() {
                        arena.wrap(c.position)
                    } else {
                        c.position
                    },
                    vel: c.velocity,
                    t_at: 0.0,
                    radius: c.radius,
                })
                .collect(),
            inv_mass: circles.iter().map(CircleState::inv_mass).collect(),
            counter: vec![0; n],
            event: vec![
                Event {
                    kind: Kind::Idle,
                    partner: NONE,
                    partner_count: 0
                };
                n
            ],
            best_pair: vec![NO_PAIR; n],
            queue: EventQueue::new(n),
            cells: CellMembers::new(grid.len(), n),
            grid,
            cell_x: vec![0; n],
            cell_y: vec![0; n],
            stats: EventStats::default(),
            segments,
            segment_cells,
            own_restitution: Vec::new(),
            hits: None,
            growth: 0.0,
            large,
            reach,
        };
        engine.relink_all();
        engine.predict_all();
        engine
    }

    /// Gives each circle its own restitution (one value per circle, in order; empty: all take
    /// the engine's). Pairs and wall hits then bounce with [`combine_restitution`].
    pub fn set_own_restitutions(&mut self, restitutions: Vec<f64>) {
        assert!(restitutions.is_empty() || restitutions.len() == self.len());
        self.own_restitution = restitutions;
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
        self.motion[i].pos = position;
        self.motion[i].vel = velocity;
        self.motion[i].t_at = self.now;
        self.counter[i] += 1;
        let listed = self.large_reach(i).is_none();
        if listed {
            self.cells.remove(i, self.cell_index(i));
        }
        let (x, y) = self.grid.cell_of(position);
        (self.cell_x[i], self.cell_y[i]) = (x as u32, y as u32);
        if listed {
            self.cells.insert(i, self.grid.index(x, y));
        }
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
        self.inside(self.motion[i].at(self.now))
    }

    /// Velocity of circle `i`.
    #[inline]
    pub fn velocity(&self, i: usize) -> DVec2 {
        self.motion[i].vel
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
            if processed == max_events {
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

    /// Moves every circle in a straight line to `t` without processing events (walls fold the
    /// motion back inside, periodic edges wrap), then predicts afresh. The fallback when a step's
    /// event budget runs out: collisions skipped here show up as overlapping, approaching pairs,
    /// which collide at once on the next advance.
    pub fn drift_to(&mut self, t: f64) {
        let arena = self.arena;
        let scale = 1.0 + self.growth * t;
        for (m, count) in self.motion.iter_mut().zip(&mut self.counter) {
            let mut p = m.at(t);
            if arena.is_periodic() {
                p = arena.wrap(p);
            } else {
                let r = m.radius * scale;
                reflect_off_walls(&mut p, &mut m.vel, r, &arena, self.wall_restitution);
            }
            m.pos = p;
            m.t_at = t;
            *count += 1;
        }
        self.now = t;
        self.relink_all();
        self.predict_all();
    }

    /// Moves circle `i`'s reference point to time `t`, where its course is about to change
    /// (inside a periodic arena). Crossings never move it: only events that every grid of cells
    /// shares do, so the trajectories do not depend on the grid.
    fn advance_circle(&mut self, i: usize, t: f64) {
        let p = self.motion[i].at(t);
        self.motion[i].pos = self.inside(p);
        self.motion[i].t_at = t;
    }

    /// `p`, or on a periodic arena its image in `[min, max)`.
    #[inline]
    fn inside(&self, p: DVec2) -> DVec2 {
        let arena = &self.arena;
        if self.grid.periodic && !(p.cmpge(arena.min).all() && p.cmplt(arena.max).all()) {
            arena.wrap(p)
        } else {
            p
        }
    }

    /// The displacement from `a` to `b` (minimum image on a periodic arena).
    #[inline]
    fn offset(&self, a: DVec2, b: DVec2) -> DVec2 {
        if self.grid.periodic {
            minimum_image(b - a, self.period)
        } else {
            b - a
        }
    }

    fn cell_index(&self, i: usize) -> usize {
        self.grid
            .index(self.cell_x[i] as usize, self.cell_y[i] as usize)
    }

    /// Puts every circle in the cell its current position lies in (large circles in none, but
    /// each still knows its cell).
    fn relink_all(&mut self) {
        self.cells.clear();
        for i in 0..self.len() {
            let (x, y) = self.grid.cell_of(self.motion[i].pos);
            self.cell_x[i] = x as u32;
            self.cell_y[i] = y as u32;
            if self.large_reach(i).is_none() {
                self.cells.insert(i, self.grid.index(x, y));
            }
        }
    }

    fn collide(&mut self, i: usize, j: usize) {
        let now = self.now;
        self.advance_circle(i, now);
        self.advance_circle(j, now);
        let (a, b) = (self.motion[i], self.motion[j]);
        let (n, _) = contact_normal(self.offset(a.pos, b.pos), a.vel - b.vel);
        let (mut va, mut vb) = (a.vel, b.vel);
        let (wa, wb) = (self.inv_mass[i], self.inv_mass[j]);
        let e = match self.own_restitution.as_slice() {
            [] => self.restitution,
            own => combine_restitution(own[i], own[j]),
        };
        // Growing radii bounce as if `b` came in slower by the rate the surfaces close at.
        let surfaces = n * ((a.radius + b.radius) * self.growth);
        vb -= surfaces;
        if let Some(impulse) = apply_impulse(n, &mut va, &mut vb, wa, wb, e) {
            self.motion[i].vel = va;
            self.motion[j].vel = vb + surfaces;
            self.stats.pair_collisions += 1;
            self.stats.virial += (a.radius + b.radius) * impulse;
            if wa == 0.0 || wb == 0.0 {
                let (work, gained) = work_by_immovable((wa, wb), (a.vel, va), (b.vel, vb));
                self.stats.immovable_work += work;
                self.stats.immovable_impulse += gained;
            }
            if let Some(log) = &mut self.hits {
                log.circles.push(CircleHit {
                    a: i as u32,
                    b: j as u32,
                    point: a.pos + n * a.radius,
                    normal: n,
                    impulse,
                    normal_speed: (a.vel - b.vel).dot(n),
                    time: now,
                });
            }
        }
        self.counter[i] += 1;
        self.counter[j] += 1;
        self.predict(i);
        self.predict(j);
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
        *cell = if up {
            (*cell + 1) % count
        } else {
            (*cell + count - 1) % count
        };
        if listed {
            self.cells.insert(i, self.cell_index(i));
        }
        self.predict_after_crossing(i, axis, up);
    }
}
