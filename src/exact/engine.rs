//! The event-driven engine: circles fly in straight lines between events, and events (pair
//! collisions, wall hits, cell crossings) are processed in time order from a priority queue.
//! Events carry the collision counters of the circles they involve; an event whose counters
//! no longer match was invalidated by an earlier event and is dropped when popped.
//!
//! Each circle keeps only its soonest predicted event in the queue (so the queue holds about N
//! events, not one per neighbour): when an event pops whose owner is unchanged but whose partner
//! has moved on, nothing can have happened to the owner before it, so the owner is simply
//! predicted again from that moment.
//!
//! Positions are advanced lazily: circle `i` is at `pos[i] + vel[i]·(t - t_at[i])`. A cell list
//! (cells at least one largest diameter wide, tracked through cell-crossing events) keeps
//! prediction local. Everything is f64.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use bevy::math::DVec2;

use super::toi::{pair_time_of_impact, wall_time_of_impact};
use crate::boundary::minimum_image;

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
    fn min_and_size(self) -> (DVec2, DVec2) {
        match self {
            Bounds::Walls { min, max } => (min, max - min),
            Bounds::Periodic { min, size } => (min, size),
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
    /// Events popped that had been invalidated.
    pub stale_events: u64,

    /// Momentum taken up by the walls, `Σ m |Δv|`.
    pub wall_impulse: f64,
    /// `Σ (r_a + r_b) · j` over collisions.
    pub virial: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Pair,
    Wall { axis: u8 },
    Cell { axis: u8, up: bool },
}

#[derive(Clone, Copy, Debug)]
struct Event {
    time: f64,
    kind: Kind,
    i: u32,
    j: u32,
    count_i: u32,
    count_j: u32,
}

impl Event {
    fn key(&self) -> (u32, u32, u8) {
        let k = match self.kind {
            Kind::Pair => 0,
            Kind::Wall { axis } => 1 + axis,
            Kind::Cell { axis, .. } => 3 + axis,
        };
        (self.i, self.j, k)
    }
}

impl PartialEq for Event {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Event {
    /// Reversed, so the max-heap pops the earliest event; ties broken by circle indices so the
    /// order never depends on insertion history.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .time
            .total_cmp(&self.time)
            .then_with(|| other.key().cmp(&self.key()))
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
    pos: Vec<DVec2>,
    vel: Vec<DVec2>,
    t_at: Vec<f64>,
    radius: Vec<f64>,
    inv_mass: Vec<f64>,
    counter: Vec<u32>,
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
    queue: BinaryHeap<Event>,
    stats: EventStats,
}

impl EventEngine {
    /// Builds the engine at time 0 and predicts every circle's first events. Circles must have
    /// finite state; with walls their centres must lie within `[min + r, max - r]` (a centre
    /// just outside by rounding is treated as touching the wall).
    pub fn new(
        circles: &[Circle],
        bounds: Bounds,
        restitution: f64,
        wall_restitution: f64,
    ) -> Self {
        let n = circles.len();
        let (origin, size) = bounds.min_and_size();
        let largest = circles.iter().map(|c| c.radius).fold(0.0f64, f64::max);
        // Cells at least one largest diameter wide, and no more than about 4 per circle.
        let per_axis_cap = ((4 * n).max(1) as f64).sqrt().ceil().max(1.0);
        let count = |length: f64| {
            let fit = (length / (2.0 * largest).max(f64::MIN_POSITIVE)).floor();
            fit.clamp(1.0, per_axis_cap) as usize
        };
        let (cols, rows) = (count(size.x), count(size.y));
        let mut engine = Self {
            bounds,
            restitution,
            wall_restitution,
            now: 0.0,
            pos: circles.iter().map(|c| c.position).collect(),
            vel: circles.iter().map(|c| c.velocity).collect(),
            t_at: vec![0.0; n],
            radius: circles.iter().map(|c| c.radius).collect(),
            inv_mass: circles.iter().map(|c| c.inv_mass).collect(),
            counter: vec![0; n],
            origin,
            cell: DVec2::new(size.x / cols as f64, size.y / rows as f64),
            cols,
            rows,
            cell_x: vec![0; n],
            cell_y: vec![0; n],
            head: vec![NONE; cols * rows],
            next: vec![NONE; n],
            prev: vec![NONE; n],
            queue: BinaryHeap::with_capacity(16 * n + 16),
            stats: EventStats::default(),
        };
        for i in 0..n {
            if let Bounds::Periodic { .. } = bounds {
                engine.pos[i] = crate::boundary::wrap_into(
                    engine.pos[i],
                    &crate::config::Arena {
                        min: origin,
                        max: origin + size,
                    },
                );
            }
            let c = ((engine.pos[i] - origin) / engine.cell).floor();
            engine.cell_x[i] = (c.x.max(0.0) as usize).min(cols - 1) as u32;
            engine.cell_y[i] = (c.y.max(0.0) as usize).min(rows - 1) as u32;
            engine.link(i);
        }
        engine.predict_all();
        engine
    }

    /// Current simulated time.
    pub fn now(&self) -> f64 {
        self.now
    }

    /// Number of circles.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    /// Whether there are no circles.
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// What the engine has done so far.
    pub fn stats(&self) -> EventStats {
        self.stats
    }

    /// Position of circle `i` now.
    pub fn position(&self, i: usize) -> DVec2 {
        self.position_at(i, self.now)
    }

    /// Velocity of circle `i`.
    pub fn velocity(&self, i: usize) -> DVec2 {
        self.vel[i]
    }

    fn position_at(&self, i: usize, t: f64) -> DVec2 {
        self.pos[i] + self.vel[i] * (t - self.t_at[i])
    }

    fn advance_circle(&mut self, i: usize, t: f64) {
        self.pos[i] = self.position_at(i, t);
        self.t_at[i] = t;
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

    /// The displacement from `a` to `b` (minimum image on a periodic box).
    fn offset(&self, a: DVec2, b: DVec2) -> DVec2 {
        match self.bounds {
            Bounds::Walls { .. } => b - a,
            Bounds::Periodic { size, .. } => minimum_image(b - a, size),
        }
    }

    /// The distinct cells of the 3×3 block around circle `i`'s cell.
    fn neighbourhood(&self, i: usize) -> ([usize; 9], usize) {
        let periodic = matches!(self.bounds, Bounds::Periodic { .. });
        let (cx, cy) = (self.cell_x[i] as i64, self.cell_y[i] as i64);
        let (cols, rows) = (self.cols as i64, self.rows as i64);
        let mut cells = [0usize; 9];
        let mut len = 0;
        for dy in -1..=1 {
            for dx in -1..=1 {
                let (mut x, mut y) = (cx + dx, cy + dy);
                if periodic {
                    x = x.rem_euclid(cols);
                    y = y.rem_euclid(rows);
                } else if x < 0 || y < 0 || x >= cols || y >= rows {
                    continue;
                }
                let c = (y * cols + x) as usize;
                if !cells[..len].contains(&c) {
                    cells[len] = c;
                    len += 1;
                }
            }
        }
        (cells, len)
    }

    fn push(&mut self, time: f64, kind: Kind, i: usize, j: u32) {
        let count_j = if j == NONE {
            0
        } else {
            self.counter[j as usize]
        };
        self.queue.push(Event {
            time,
            kind,
            i: i as u32,
            j,
            count_i: self.counter[i],
            count_j,
        });
    }

    /// Predicts circle `i`'s soonest event from `now` — a pair collision within its
    /// neighbourhood, a wall hit or a cell crossing — and queues it.
    fn predict(&mut self, i: usize) {
        let now = self.now;
        let p = self.position_at(i, now);
        let v = self.vel[i];
        let mut soonest: Option<(f64, Kind, u32)> = None;
        let mut consider = |t: f64, kind: Kind, j: u32| {
            if soonest.is_none_or(|(best, _, _)| t < best) {
                soonest = Some((t, kind, j));
            }
        };
        let (cells, len) = self.neighbourhood(i);
        for &c in &cells[..len] {
            let mut j = self.head[c];
            while j != NONE {
                let ju = j as usize;
                if ju != i {
                    let dp = self.offset(p, self.position_at(ju, now));
                    let dv = self.vel[ju] - v;
                    if let Some(t) = pair_time_of_impact(dp, dv, self.radius[i] + self.radius[ju]) {
                        consider(t, Kind::Pair, j);
                    }
                }
                j = self.next[ju];
            }
        }
        for axis in 0..2u8 {
            let a = axis as usize;
            if v[a] == 0.0 {
                continue;
            }
            if let Bounds::Walls { min, max } = self.bounds {
                let r = self.radius[i];
                if let Some((t, _)) = wall_time_of_impact(p[a], v[a], min[a] + r, max[a] - r) {
                    consider(t, Kind::Wall { axis }, NONE);
                }
            }
            // Cell crossing along this axis (none past the outer cells of a walled box).
            let cell = if a == 0 {
                self.cell_x[i]
            } else {
                self.cell_y[i]
            } as usize;
            let last = if a == 0 { self.cols } else { self.rows } - 1;
            let up = v[a] > 0.0;
            let walls = matches!(self.bounds, Bounds::Walls { .. });
            if walls && ((up && cell == last) || (!up && cell == 0)) {
                continue;
            }
            let edge = self.origin[a] + self.cell[a] * (cell + usize::from(up)) as f64;
            let t = ((edge - p[a]) / v[a]).max(0.0);
            consider(t, Kind::Cell { axis, up }, NONE);
        }
        if let Some((t, kind, j)) = soonest {
            self.push(now + t, kind, i, j);
        }
    }

    fn predict_all(&mut self) {
        self.queue.clear();
        for i in 0..self.len() {
            self.predict(i);
        }
    }

    fn owner_unchanged(&self, e: &Event) -> bool {
        self.counter[e.i as usize] == e.count_i
    }

    fn partner_unchanged(&self, e: &Event) -> bool {
        e.j == NONE || self.counter[e.j as usize] == e.count_j
    }

    /// Processes every event up to time `t_end` and moves the clock there. Stops early (with the
    /// clock at the last processed event) after `max_events` valid events.
    pub fn advance_to(&mut self, t_end: f64, max_events: u64) -> Result<u64, BudgetExhausted> {
        let mut processed = 0;
        while let Some(&event) = self.queue.peek() {
            if event.time > t_end {
                break;
            }
            self.queue.pop();
            if !self.owner_unchanged(&event) {
                self.stats.stale_events += 1;
                continue;
            }
            if !self.partner_unchanged(&event) {
                // The partner moved on; the owner's path is unchanged up to now: predict again.
                self.stats.stale_events += 1;
                self.now = event.time.max(self.now);
                self.predict(event.i as usize);
                continue;
            }
            if processed == max_events {
                self.queue.push(event);
                return Err(BudgetExhausted { events: processed });
            }
            processed += 1;
            self.now = event.time.max(self.now);
            match event.kind {
                Kind::Pair => self.collide(event.i as usize, event.j as usize),
                Kind::Wall { axis } => self.hit_wall(event.i as usize, axis as usize),
                Kind::Cell { axis, up } => self.cross_cell(event.i as usize, axis as usize, up),
            }
            // Each circle has one live event; the rest are stale. Start afresh if they pile up.
            if self.queue.len() > 8 * self.len() + 1024 {
                self.predict_all();
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
        let (origin, size) = self.bounds.min_and_size();
        let arena = crate::config::Arena {
            min: origin,
            max: origin + size,
        };
        for i in 0..self.len() {
            let mut p = self.position_at(i, t);
            match self.bounds {
                Bounds::Walls { .. } => {
                    let mut v = self.vel[i];
                    crate::boundary::reflect_off_walls(
                        &mut p,
                        &mut v,
                        self.radius[i],
                        &arena,
                        self.wall_restitution,
                    );
                    self.vel[i] = v;
                }
                Bounds::Periodic { .. } => p = crate::boundary::wrap_into(p, &arena),
            }
            self.pos[i] = p;
            self.t_at[i] = t;
            self.counter[i] += 1;
        }
        self.now = t;
        self.head.fill(NONE);
        for i in 0..self.len() {
            let c = ((self.pos[i] - origin) / self.cell).floor();
            self.cell_x[i] = (c.x.max(0.0) as usize).min(self.cols - 1) as u32;
            self.cell_y[i] = (c.y.max(0.0) as usize).min(self.rows - 1) as u32;
            self.link(i);
        }
        self.predict_all();
    }

    fn collide(&mut self, i: usize, j: usize) {
        let now = self.now;
        self.advance_circle(i, now);
        self.advance_circle(j, now);
        let d = self.offset(self.pos[i], self.pos[j]);
        let dist = d.length();
        let n = if dist > 0.0 {
            d / dist
        } else {
            (self.vel[i] - self.vel[j])
                .try_normalize()
                .unwrap_or(DVec2::X)
        };
        let approach = (self.vel[j] - self.vel[i]).dot(n);
        let w = self.inv_mass[i] + self.inv_mass[j];
        if approach < 0.0 && w > 0.0 {
            let impulse = -(1.0 + self.restitution) * approach / w;
            self.vel[i] -= n * (impulse * self.inv_mass[i]);
            self.vel[j] += n * (impulse * self.inv_mass[j]);
            self.stats.pair_collisions += 1;
            self.stats.virial += (self.radius[i] + self.radius[j]) * impulse;
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
        let r = self.radius[i];
        let (lo, hi) = (min[axis] + r, max[axis] - r);
        let v = self.vel[i][axis];
        // Snap onto the wall (the event time puts it there up to rounding) and reflect.
        self.pos[i][axis] = if v > 0.0 { hi } else { lo };
        let new_v = -self.wall_restitution * v;
        if self.inv_mass[i] > 0.0 {
            self.stats.wall_impulse += (new_v - v).abs() / self.inv_mass[i];
        }
        self.vel[i][axis] = new_v;
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
            self.pos[i][axis] += wrapped * size[axis];
        }
        self.link(i);
        self.stats.cell_crossings += 1;
        self.counter[i] += 1;
        self.predict(i);
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
