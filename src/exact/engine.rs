//! The event-driven engine: circles fly in straight lines between events, and events (pair
//! collisions, wall hits, cell crossings) are processed in time order.
//!
//! Each circle has exactly one pending event, its soonest, held in an indexed [`EventQueue`].
//! A pair event remembers its partner's collision counter; if the partner has collided since,
//! the event is stale, and since nothing can have happened to the owner before it, the owner is
//! simply predicted again from that moment.
//!
//! Positions are advanced lazily: circle `i` is at `pos + vel·(t - t_at)`. A cell list (cells
//! at least one largest diameter wide, tracked through cell-crossing events) keeps prediction
//! local. A crossing changes no trajectory, so it bumps no counter (events other circles hold
//! with the crosser stay valid), and the crosser only looks at the three cells it newly
//! borders, keeping its best pair from before if that partner has not changed: whenever a pair
//! becomes neighbours, the one that moved looks at the other, and whenever a trajectory
//! changes, its owner looks at every neighbour. Everything is f64.

use bevy::math::DVec2;

use super::queue::EventQueue;
use super::toi::{pair_time_of_impact, wall_time_of_impact};
use crate::boundary::{minimum_image, reflect_off_walls, wrap_into};
use crate::config::Arena;

/// One circle as the engine takes it in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// Radius.
    pub radius: f64,
    /// `1 / mass` (0 = immovable).
    pub inv_mass: f64,
}

/// The region the circles live in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bounds {
    /// A box with walls.
    Walls {
        /// Lower-left corner.
        min: DVec2,
        /// Upper-right corner.
        max: DVec2,
    },
    /// A periodic box.
    Periodic {
        /// Lower-left corner.
        min: DVec2,
        /// Width and height.
        size: DVec2,
    },
}

impl Bounds {
    fn arena(self) -> Arena {
        match self {
            Bounds::Walls { min, max } => Arena { min, max },
            Bounds::Periodic { min, size } => Arena {
                min,
                max: min + size,
            },
        }
    }
}

/// Counts of what the engine did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EventStats {
    /// Circle-circle collisions processed.
    pub pair_collisions: u64,
    /// Wall hits processed.
    pub wall_collisions: u64,
    /// Cell crossings processed.
    pub cell_crossings: u64,
    /// Pair events dropped because the partner had collided since (the owner was predicted
    /// again instead).
    pub stale_events: u64,

    /// Momentum taken up by the walls, `Σ m |Δv|`.
    pub wall_impulse: f64,
    /// `Σ (r_a + r_b) · j` over collisions.
    pub virial: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
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
}

/// A circle's pending event (its time lives in the queue).
#[derive(Clone, Copy, Debug)]
struct Event {
    kind: Kind,
    partner: u32,
    partner_count: u32,
}

/// The soonest pair collision a circle's last look at its neighbours found.
#[derive(Clone, Copy, Debug)]
struct BestPair {
    time: f64,
    partner: u32,
    partner_count: u32,
}

const NO_PAIR: BestPair = BestPair {
    time: f64::INFINITY,
    partner: NONE,
    partner_count: 0,
};

/// What prediction reads for each circle, kept together for the cache.
#[derive(Clone, Copy, Debug)]
struct Motion {
    /// Position at time `t_at`.
    pos: DVec2,
    vel: DVec2,
    t_at: f64,
    radius: f64,
}

impl Motion {
    #[inline]
    fn at(&self, t: f64) -> DVec2 {
        self.pos + self.vel * (t - self.t_at)
    }
}

const NONE: u32 = u32::MAX;

/// Why [`EventEngine::advance_to`] stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BudgetExhausted {
    /// Events processed before giving up.
    pub events: u64,
}

/// An event-driven simulation of circles.
#[derive(Clone, Debug)]
pub struct EventEngine {
    bounds: Bounds,
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
    // Cell list: doubly linked lists per cell, membership updated by crossing events.
    origin: DVec2,
    cell: DVec2,
    cols: usize,
    rows: usize,
    cell_x: Vec<u32>,
    cell_y: Vec<u32>,
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    stats: EventStats,
}

impl EventEngine {
    /// Builds the engine at time 0 and predicts every circle's first event. Circles must have
    /// finite state; with walls their centres must lie within `[min + r, max - r]` (a centre
    /// just outside by rounding is treated as touching the wall).
    pub fn new(
        circles: &[Circle],
        bounds: Bounds,
        restitution: f64,
        wall_restitution: f64,
    ) -> Self {
        let n = circles.len();
        let arena = bounds.arena();
        let size = arena.size();
        let largest = circles.iter().map(|c| c.radius).fold(0.0f64, f64::max);
        // Cells at least one largest diameter wide, and no more than about 4 per circle.
        let per_axis_cap = ((4 * n).max(1) as f64).sqrt().ceil().max(1.0);
        let count = |length: f64| {
            let fit = (length / (2.0 * largest).max(f64::MIN_POSITIVE)).floor();
            fit.clamp(1.0, per_axis_cap) as usize
        };
        let (cols, rows) = (count(size.x), count(size.y));
        let periodic = matches!(bounds, Bounds::Periodic { .. });
        let mut engine = Self {
            bounds,
            restitution,
            wall_restitution,
            now: 0.0,
            motion: circles
                .iter()
                .map(|c| Motion {
                    pos: if periodic {
                        wrap_into(c.position, &arena)
                    } else {
                        c.position
                    },
                    vel: c.velocity,
                    t_at: 0.0,
                    radius: c.radius,
                })
                .collect(),
            inv_mass: circles.iter().map(|c| c.inv_mass).collect(),
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
            origin: arena.min,
            cell: DVec2::new(size.x / cols as f64, size.y / rows as f64),
            cols,
            rows,
            cell_x: vec![0; n],
            cell_y: vec![0; n],
            head: vec![NONE; cols * rows],
            next: vec![NONE; n],
            prev: vec![NONE; n],
            stats: EventStats::default(),
        };
        engine.relink_all();
        engine.predict_all();
        engine
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

    /// Position of circle `i` now.
    pub fn position(&self, i: usize) -> DVec2 {
        self.motion[i].at(self.now)
    }

    /// Velocity of circle `i`.
    pub fn velocity(&self, i: usize) -> DVec2 {
        self.motion[i].vel
    }

    fn advance_circle(&mut self, i: usize, t: f64) {
        let m = &mut self.motion[i];
        m.pos = m.at(t);
        m.t_at = t;
    }

    fn cell_index(&self, i: usize) -> usize {
        self.cell_y[i] as usize * self.cols + self.cell_x[i] as usize
    }

    fn link(&mut self, i: usize) {
        let c = self.cell_index(i);
        let first = self.head[c];
        self.next[i] = first;
        self.prev[i] = NONE;
        if first != NONE {
            self.prev[first as usize] = i as u32;
        }
        self.head[c] = i as u32;
    }

    fn unlink(&mut self, i: usize) {
        let (p, n) = (self.prev[i], self.next[i]);
        if p != NONE {
            self.next[p as usize] = n;
        } else {
            let c = self.cell_index(i);
            self.head[c] = n;
        }
        if n != NONE {
            self.prev[n as usize] = p;
        }
    }

    /// Puts every circle in the cell its current position lies in.
    fn relink_all(&mut self) {
        self.head.fill(NONE);
        for i in 0..self.len() {
            let c = ((self.motion[i].pos - self.origin) / self.cell).floor();
            self.cell_x[i] = (c.x.max(0.0) as usize).min(self.cols - 1) as u32;
            self.cell_y[i] = (c.y.max(0.0) as usize).min(self.rows - 1) as u32;
            self.link(i);
        }
    }

    /// The displacement from `a` to `b` (minimum image on a periodic box).
    #[inline]
    fn offset(&self, a: DVec2, b: DVec2) -> DVec2 {
        match self.bounds {
            Bounds::Walls { .. } => b - a,
            Bounds::Periodic { size, .. } => minimum_image(b - a, size),
        }
    }

    /// Cell `(x + dx, y + dy)`, wrapped on a periodic box, `None` past a wall.
    #[inline]
    fn shifted_cell(&self, x: u32, y: u32, dx: i64, dy: i64) -> Option<usize> {
        let (cols, rows) = (self.cols as i64, self.rows as i64);
        let (mut x, mut y) = (x as i64 + dx, y as i64 + dy);
        if matches!(self.bounds, Bounds::Periodic { .. }) {
            x = x.rem_euclid(cols);
            y = y.rem_euclid(rows);
        } else if x < 0 || y < 0 || x >= cols || y >= rows {
            return None;
        }
        Some((y * cols + x) as usize)
    }

    /// The soonest collision of circle `i` with a circle in `cells`, as seen from now.
    fn scan(&self, i: usize, cells: impl IntoIterator<Item = usize>) -> BestPair {
        let now = self.now;
        let me = self.motion[i];
        let p = me.at(now);
        let mut best = NO_PAIR;
        for c in cells {
            let mut j = self.head[c];
            while j != NONE {
                let ju = j as usize;
                let other = &self.motion[ju];
                if ju != i {
                    let dp = self.offset(p, other.at(now));
                    if let Some(t) =
                        pair_time_of_impact(dp, other.vel - me.vel, me.radius + other.radius)
                        && now + t < best.time
                    {
                        best = BestPair {
                            time: now + t,
                            partner: j,
                            partner_count: self.counter[ju],
                        };
                    }
                }
                j = self.next[ju];
            }
        }
        best
    }

    /// Looks at every circle in the 3×3 block of cells around circle `i` and schedules its
    /// soonest event.
    fn predict(&mut self, i: usize) {
        let (x, y) = (self.cell_x[i], self.cell_y[i]);
        let (xu, yu) = (x as usize, y as usize);
        if (1..self.cols - 1).contains(&xu) && (1..self.rows - 1).contains(&yu) {
            // Away from the edges: nine distinct cells, no wrapping.
            let c = self.cell_index(i);
            let cols = self.cols;
            let block = [c - cols, c, c + cols]
                .into_iter()
                .flat_map(|middle| [middle - 1, middle, middle + 1]);
            self.best_pair[i] = self.scan(i, block);
            self.schedule(i);
            return;
        }
        let mut cells = [0usize; 9];
        let mut len = 0;
        for dy in -1..=1 {
            for dx in -1..=1 {
                // Tiny periodic grids wrap a cell onto itself; visit each once.
                if let Some(c) = self.shifted_cell(x, y, dx, dy)
                    && !cells[..len].contains(&c)
                {
                    cells[len] = c;
                    len += 1;
                }
            }
        }
        self.best_pair[i] = self.scan(i, cells[..len].iter().copied());
        self.schedule(i);
    }

    /// After circle `i` crossed into a new cell along `axis`: looks only at the three cells it
    /// now borders for the first time and keeps the sooner of what it finds there and its best
    /// pair from before. If that partner has collided since, the pair event is found stale when
    /// it comes up and the circle looks at all its neighbours then, before anything it could
    /// have missed.
    fn predict_after_crossing(&mut self, i: usize, axis: usize, up: bool) {
        let best = self.best_pair[i];
        let (x, y) = (self.cell_x[i], self.cell_y[i]);
        let ahead = if up { 1 } else { -1 };
        let cells = (-1..=1).filter_map(|side| {
            let (dx, dy) = if axis == 0 {
                (ahead, side)
            } else {
                (side, ahead)
            };
            self.shifted_cell(x, y, dx, dy)
        });
        let found = self.scan(i, cells);
        if found.time < best.time {
            self.best_pair[i] = found;
        }
        self.schedule(i);
    }

    /// Sets circle `i`'s event to the soonest of its best pair, a wall hit and a cell crossing.
    fn schedule(&mut self, i: usize) {
        let m = self.motion[i];
        let p = m.at(self.now);
        let best = self.best_pair[i];
        let (mut time, mut event) = (
            best.time,
            Event {
                kind: if best.partner == NONE {
                    Kind::Idle
                } else {
                    Kind::Pair
                },
                partner: best.partner,
                partner_count: best.partner_count,
            },
        );
        let mut consider = |t: f64, kind: Kind| {
            if t < time {
                time = t;
                event = Event {
                    kind,
                    partner: NONE,
                    partner_count: 0,
                };
            }
        };
        let walls = matches!(self.bounds, Bounds::Walls { .. });
        for axis in 0..2u8 {
            let a = axis as usize;
            let v = m.vel[a];
            if v == 0.0 {
                continue;
            }
            if let Bounds::Walls { min, max } = self.bounds
                && let Some((t, _)) =
                    wall_time_of_impact(p[a], v, min[a] + m.radius, max[a] - m.radius)
            {
                consider(self.now + t, Kind::Wall { axis });
            }
            // Cell crossing along this axis (none past the outer cells of a walled box).
            let (cell, last) = if a == 0 {
                (self.cell_x[i] as usize, self.cols - 1)
            } else {
                (self.cell_y[i] as usize, self.rows - 1)
            };
            let up = v > 0.0;
            if walls && ((up && cell == last) || (!up && cell == 0)) {
                continue;
            }
            let edge = self.origin[a] + self.cell[a] * (cell + usize::from(up)) as f64;
            consider(
                self.now + ((edge - p[a]) / v).max(0.0),
                Kind::Cell { axis, up },
            );
        }
        self.event[i] = event;
        self.queue.set(i, time);
    }

    fn predict_all(&mut self) {
        for i in 0..self.len() {
            self.predict(i);
        }
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
                self.stats.stale_events += 1;
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
        let arena = self.bounds.arena();
        for (m, count) in self.motion.iter_mut().zip(&mut self.counter) {
            let mut p = m.at(t);
            match self.bounds {
                Bounds::Walls { .. } => {
                    reflect_off_walls(&mut p, &mut m.vel, m.radius, &arena, self.wall_restitution);
                }
                Bounds::Periodic { .. } => p = wrap_into(p, &arena),
            }
            m.pos = p;
            m.t_at = t;
            *count += 1;
        }
        self.now = t;
        self.relink_all();
        self.predict_all();
    }

    fn collide(&mut self, i: usize, j: usize) {
        let now = self.now;
        self.advance_circle(i, now);
        self.advance_circle(j, now);
        let (a, b) = (self.motion[i], self.motion[j]);
        let d = self.offset(a.pos, b.pos);
        let dist = d.length();
        let n = if dist > 0.0 {
            d / dist
        } else {
            (a.vel - b.vel).try_normalize().unwrap_or(DVec2::X)
        };
        let approach = (b.vel - a.vel).dot(n);
        let w = self.inv_mass[i] + self.inv_mass[j];
        if approach < 0.0 && w > 0.0 {
            let impulse = -(1.0 + self.restitution) * approach / w;
            self.motion[i].vel -= n * (impulse * self.inv_mass[i]);
            self.motion[j].vel += n * (impulse * self.inv_mass[j]);
            self.stats.pair_collisions += 1;
            self.stats.virial += (a.radius + b.radius) * impulse;
        }
        self.counter[i] += 1;
        self.counter[j] += 1;
        self.predict(i);
        self.predict(j);
    }

    fn hit_wall(&mut self, i: usize, axis: usize) {
        let Bounds::Walls { min, max } = self.bounds else {
            return;
        };
        self.advance_circle(i, self.now);
        let m = &mut self.motion[i];
        let (lo, hi) = (min[axis] + m.radius, max[axis] - m.radius);
        let v = m.vel[axis];
        // Snap onto the wall (the event time puts it there up to rounding) and reflect.
        m.pos[axis] = if v > 0.0 { hi } else { lo };
        let new_v = -self.wall_restitution * v;
        m.vel[axis] = new_v;
        if self.inv_mass[i] > 0.0 {
            self.stats.wall_impulse += (new_v - v).abs() / self.inv_mass[i];
        }
        self.stats.wall_collisions += 1;
        self.counter[i] += 1;
        self.predict(i);
    }

    fn cross_cell(&mut self, i: usize, axis: usize, up: bool) {
        self.advance_circle(i, self.now);
        self.unlink(i);
        let (count, cell) = if axis == 0 {
            (self.cols as u32, &mut self.cell_x[i])
        } else {
            (self.rows as u32, &mut self.cell_y[i])
        };
        let mut wrapped = 0.0;
        if up {
            *cell += 1;
            if *cell == count {
                *cell = 0;
                wrapped = -1.0;
            }
        } else if *cell == 0 {
            *cell = count - 1;
            wrapped = 1.0;
        } else {
            *cell -= 1;
        }
        if wrapped != 0.0
            && let Bounds::Periodic { size, .. } = self.bounds
        {
            self.motion[i].pos[axis] += wrapped * size[axis];
        }
        self.link(i);
        self.stats.cell_crossings += 1;
        self.predict_after_crossing(i, axis, up);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(x: f64, y: f64, vx: f64, vy: f64, r: f64) -> Circle {
        Circle {
            position: DVec2::new(x, y),
            velocity: DVec2::new(vx, vy),
            radius: r,
            inv_mass: 1.0,
        }
    }

    fn walls(size: f64) -> Bounds {
        Bounds::Walls {
            min: DVec2::ZERO,
            max: DVec2::splat(size),
        }
    }

    #[test]
    fn a_head_on_pair_swaps_velocities_at_the_right_time() {
        let mut e = EventEngine::new(
            &[
                circle(2.0, 5.0, 1.0, 0.0, 0.5),
                circle(6.0, 5.0, -1.0, 0.0, 0.5),
            ],
            walls(10.0),
            1.0,
            1.0,
        );
        e.advance_to(1.49, u64::MAX).unwrap();
        assert_eq!(e.stats().pair_collisions, 0);
        e.advance_to(1.51, u64::MAX).unwrap();
        assert_eq!(e.stats().pair_collisions, 1);
        assert_eq!(e.velocity(0), DVec2::new(-1.0, 0.0));
        assert!(
            (e.position(0).x - (3.5 - 0.01)).abs() < 1e-12,
            "{}",
            e.position(0)
        );
    }

    #[test]
    fn walls_reflect_exactly() {
        let mut e = EventEngine::new(&[circle(5.0, 5.0, 3.0, 0.0, 0.5)], walls(10.0), 1.0, 1.0);
        e.advance_to(2.0, u64::MAX).unwrap();
        // 4.5 to the wall (1.5 s), back 1.5 in 0.5 s.
        assert!((e.position(0).x - 8.0).abs() < 1e-12);
        assert_eq!(e.velocity(0), DVec2::new(-3.0, 0.0));
    }

    #[test]
    fn periodic_circles_wrap_through_cell_crossings() {
        let bounds = Bounds::Periodic {
            min: DVec2::ZERO,
            size: DVec2::splat(10.0),
        };
        let mut e = EventEngine::new(&[circle(9.0, 5.0, 2.0, 0.0, 0.5)], bounds, 1.0, 1.0);
        e.advance_to(1.0, u64::MAX).unwrap();
        assert!((e.position(0).x - 1.0).abs() < 1e-12, "{}", e.position(0));
    }

    #[test]
    fn the_budget_stops_work_and_says_so() {
        let mut e = EventEngine::new(&[circle(5.0, 5.0, 100.0, 0.0, 0.5)], walls(10.0), 1.0, 1.0);
        assert_eq!(e.advance_to(10.0, 5), Err(BudgetExhausted { events: 5 }));
    }
}
