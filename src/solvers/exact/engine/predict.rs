//! Prediction: a circle's soonest event among its best pair, a wall hit, a segment wall hit and
//! a cell crossing.
//!
//! Whenever a trajectory changes, its owner looks at every neighbour (the 3×3 block of cells,
//! and every large circle); after a cell crossing, which changes no trajectory, the crosser looks
//! only at the three cells it newly borders (and again at every large circle) and keeps its best
//! pair from before if that partner has not changed. So whenever a pair becomes neighbours, the
//! one that moved looks at the other. A large circle does the same over the block of cells its
//! radius reaches ([`super::large`]).
//!
//! Under gravity the same is done for parabolas: two falling circles still close at a constant
//! velocity, so a pair of them takes the straight-line time of impact; a falling circle against
//! one that does not fall takes the quartic of [`crate::collision::fall`], and walls, segment walls
//! and cell edges the parabola's roots. A sleeping circle is at rest: it predicts its pairs
//! with the circles that fly (the pair a circle falling asleep may now have with a neighbour is
//! found that way), and no wall or cell event.

use bevy::math::DVec2;

use super::EventEngine;
use super::events::{BestPair, Event, Kind, Motion, NO_PAIR, relative};
use super::motion::whole_periods;
use crate::base::grid::NONE;
use crate::collision::fall::{exit_time, falling_pair_time, falling_segment_time};
use crate::collision::toi::{
    growing_pair_time_of_impact, pair_time_of_impact, segment_time_of_impact, wall_time_of_impact,
};

impl EventEngine {
    /// The soonest collision of circle `i` with a circle in `cells` or a large circle that it
    /// meets, not before now.
    pub(super) fn scan(&self, i: usize, cells: impl IntoIterator<Item = usize>) -> BestPair {
        if !self.pairs {
            return NO_PAIR;
        }
        if self.images_wrap && self.gravity == DVec2::ZERO {
            self.scan_with::<false, true>(i, cells)
        } else if self.gravity == DVec2::ZERO {
            self.scan_with::<false, false>(i, cells)
        } else {
            self.scan_with::<true, false>(i, cells)
        }
    }

    /// [`EventEngine::scan`] over a whole block of cells: for circles on straight lines with
    /// radii that do not grow, through the nearest image, where the processor has AVX2 and
    /// [`crate::base::vector::allow`] lets it, four pairs at a time ([`super::batch`]; a few
    /// neighbours, as in the cells a crossing newly borders, are cheaper one by one).
    fn scan_block(&mut self, i: usize, cells: impl IntoIterator<Item = usize>) -> BestPair {
        #[cfg(target_arch = "x86_64")]
        if self.pairs
            && self.gravity == DVec2::ZERO
            && !self.images_wrap
            && self.growth == 0.0
            && crate::base::vector::avx2()
        {
            let mut batch = self.batch.take().unwrap_or_default();
            // SAFETY: `crate::base::vector::avx2` says the processor has AVX2.
            let best = unsafe { self.scan_straight(i, cells, &mut batch) };
            self.batch = Some(batch);
            return best;
        }
        self.scan(i, cells)
    }

    /// [`EventEngine::scan`], with the parabolas of gravity when `FALL` (a separate loop, so
    /// that the straight-line one is exactly what it is without gravity).
    fn scan_with<const FALL: bool, const IMAGES: bool>(
        &self,
        i: usize,
        cells: impl IntoIterator<Item = usize>,
    ) -> BestPair {
        let meets = self.meeting(i);
        let me = self.motion[i];
        let mut best = NO_PAIR;
        let nearest = |d: DVec2| self.nearest_image(d);
        let mut look = |j: usize| {
            if FALL {
                self.look_falling(i, j, nearest, &mut best);
            } else {
                self.look_at::<IMAGES>(&me, j, nearest, &mut best);
            }
        };
        for c in cells {
            for j in self.cells.members(c) {
                if j != i && meets(j) {
                    look(j);
                }
            }
        }
        for &j in &self.large {
            if j as usize != i && meets(j as usize) {
                look(j as usize);
            }
        }
        best
    }

    /// Whether circle `i` meets a circle `j`, under their layers, as a test of `j`. With layers,
    /// a pair that does not meet has no event (a branch the same way for every neighbour
    /// without them, kept apart from the pair's arithmetic, which must stay small enough to
    /// inline).
    #[inline(always)]
    pub(super) fn meeting(&self, i: usize) -> impl Fn(usize) -> bool {
        let mine = self.layers.get(i).copied();
        move |j: usize| mine.is_none_or(|mine| mine.meets(self.layers[j]))
    }

    /// [`EventEngine::look_at`] under gravity: the pair's positions and velocities at the later
    /// of their reference times on their own courses, and the quartic when only one falls.
    #[inline(always)]
    pub(super) fn look_falling(
        &self,
        i: usize,
        j: usize,
        image: impl Fn(DVec2) -> DVec2,
        best: &mut BestPair,
    ) {
        let (me, other) = (&self.motion[i], &self.motion[j]);
        let now = self.now;
        let since = me.t_at.max(other.t_at);
        let mut dp = self.pos_at(j, since) - self.pos_at(i, since);
        let dv = self.vel_at(j, since) - self.vel_at(i, since);
        let da = self.acceleration(j) - self.acceleration(i);
        if self.grid.periodic {
            let tau = now - since;
            dp -= self.period * image(dp + dv * tau + 0.5 * da * (tau * tau));
        }
        let sum = me.radius + other.radius;
        let impact = if da == DVec2::ZERO {
            pair_time_of_impact(dp, dv, sum)
        } else {
            // Only a time sooner than the best so far can be kept; the horizon is padded by what
            // rounding `since + t` may take, so it rules out no time the comparison below keeps.
            let pad = 4.0 * f64::EPSILON * best.time.abs().max(since.abs());
            falling_pair_time(dp, dv, da, sum, best.time - since + pad)
        };
        if let Some(t) = impact
            && (since + t).max(now) < best.time
        {
            *best = BestPair {
                time: (since + t).max(now),
                partner: j as u32,
                partner_count: self.counter[j],
            };
        }
    }

    /// Keeps in `best` the sooner of it and the collision of the circle moving as `me` with
    /// circle `j`, if they collide: through the image `image` picks from where they are now
    /// relative to each other (the nearest, when predicting), or, with
    /// `IMAGES` (`walls::images_wrap`), through the soonest of it and the images up to
    /// two periods either side (each circle crosses a cell edge before it moves a cell, at
    /// least a quarter of the box, and is predicted again then).
    ///
    /// A pair's time is worked out from the later of its two last changes of course, not from
    /// now, so it depends on the two motions alone: when the pair is looked at (after which
    /// cell crossing) cannot change it, and the cell grid does not change the trajectories.
    #[inline(always)]
    pub(super) fn look_at<const IMAGES: bool>(
        &self,
        me: &Motion,
        j: usize,
        image: impl Fn(DVec2) -> DVec2,
        best: &mut BestPair,
    ) {
        let now = self.now;
        let other = &self.motion[j];
        let (since, dp, dv) = relative(me, other, self.frame(), image);
        let sum = me.radius + other.radius;
        let impact = if IMAGES && self.growth == 0.0 {
            (-2..=2)
                .flat_map(|kx| (-2..=2).map(move |ky| DVec2::new(kx as f64, ky as f64)))
                .filter_map(|k| pair_time_of_impact(dp + k * self.period, dv, sum))
                .min_by(f64::total_cmp)
        } else if self.growth == 0.0 {
            pair_time_of_impact(dp, dv, sum)
        } else {
            growing_pair_time_of_impact(
                dp,
                dv,
                sum * (1.0 + self.growth * since),
                sum * self.growth,
            )
        };
        if let Some(t) = impact
            && (since + t).max(now) < best.time
        {
            *best = BestPair {
                time: (since + t).max(now),
                partner: j as u32,
                partner_count: self.counter[j],
            };
        }
    }

    /// Looks at every circle in the 3×3 block of cells around circle `i` and schedules its
    /// soonest event.
    pub(super) fn predict(&mut self, i: usize) {
        if let Some(reach) = self.large_reach(i) {
            return self.predict_large(i, reach);
        }
        let (x, y) = (self.cell_x[i] as usize, self.cell_y[i] as usize);
        self.best_pair[i] = match self.grid.inner_block(x, y) {
            // Away from the edges: nine plain indices (an iterator costs a check at each cell).
            Some(block) => self.scan_block(i, block),
            None => {
                let (cells, len) = self.grid.block(x, y);
                self.scan_block(i, cells[..len].iter().copied())
            }
        };
        self.schedule(i);
    }

    /// After circle `i` crossed into a new cell along `axis`: looks only at the three cells it
    /// now borders for the first time and keeps the sooner of what it finds there and its best
    /// pair from before. If that partner has collided since, the pair event is found stale when
    /// it comes up and the circle looks at all its neighbours then, before anything it could
    /// have missed.
    pub(super) fn predict_after_crossing(&mut self, i: usize, axis: usize, up: bool) {
        if let Some(reach) = self.large_reach(i) {
            return self.large_after_crossing(i, axis, up, reach);
        }
        let best = self.best_pair[i];
        let (x, y) = (self.cell_x[i] as usize, self.cell_y[i] as usize);
        let found = match self.grid.inner_ahead(x, y, axis, up) {
            Some(cells) => self.scan(i, cells),
            None => self.scan(i, self.grid.ahead(x, y, axis, up)),
        };
        if found.time < best.time {
            self.best_pair[i] = found;
        }
        self.schedule(i);
    }

    /// Sets circle `i`'s event to the soonest of its best pair, a wall hit, a hit on a segment
    /// wall listed in its cell and a cell crossing. Like pair times, these are worked out from
    /// the circle's last change of course (`t_at`), never from now, and are never before now.
    pub(super) fn schedule(&mut self, i: usize) {
        let m = self.motion[i];
        let (p, since, now) = (m.pos, m.t_at, self.now);
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
        let mut consider = |t: f64, kind: Kind, partner: u32| {
            let t = (since + t).max(now);
            if t < time {
                time = t;
                event = Event {
                    kind,
                    partner,
                    partner_count: 0,
                };
            }
        };
        let acc = self.acceleration(i);
        for &k in self.segment_cells.in_cell(self.cell_index(i)) {
            let segment = &self.segments[k as usize];
            let hit = if acc == DVec2::ZERO {
                segment_time_of_impact(p, m.vel, m.radius, segment)
            } else {
                falling_segment_time(p, m.vel, acc, m.radius, segment)
            };
            if let Some(t) = hit {
                consider(t, Kind::Segment, k);
            }
        }
        let (walls, periodic) = (self.arena.has_walls(), self.grid.periodic);
        let (min, max): (DVec2, DVec2) = (self.arena.min, self.arena.max);
        let (r, growth) = (
            m.radius * (1.0 + self.growth * since),
            m.radius * self.growth,
        );
        for axis in 0..2u8 {
            let a = axis as usize;
            let v = m.vel[a];
            if acc[a] != 0.0 {
                // Under gravity: the parabola's roots, through walls and cell edges alike.
                let (lo, hi) = (min[a] + r, max[a] - r);
                if walls && let Some((t, _)) = exit_time(p[a], v, acc[a], lo, hi) {
                    consider(t, Kind::Wall { axis }, NONE);
                }
                if let Some((t, up)) = self.cell_exit(i, a, acc[a]) {
                    consider(t, Kind::Cell { axis, up }, NONE);
                }
                continue;
            }
            if walls
                && let Some((t, _)) = wall_time_of_impact(p[a], v, min[a] + r, max[a] - r, growth)
            {
                consider(t, Kind::Wall { axis }, NONE);
            }
            if v == 0.0 {
                continue;
            }
            // Cell crossing along this axis.
            let (cell, last) = if a == 0 {
                (self.cell_x[i] as usize, self.grid.cols - 1)
            } else {
                (self.cell_y[i] as usize, self.grid.rows - 1)
            };
            let up = v > 0.0;
            // None past the outer cells of a walled or open box (the outer cells of an open one
            // reach on without end), nor where one cell spans a period.
            if (!periodic && ((up && cell == last) || (!up && cell == 0))) || last == 0 {
                continue;
            }
            let mut edge = self.grid.edge(a, cell + usize::from(up));
            if periodic {
                // The reference point is in the arena, the circle may have left it by whole
                // periods since: the edge is the one in the circle's own image of the arena,
                // found from where it is now (within half a cell of its cell, and with two
                // cells or more a cell is at most half a period).
                let middle = self.grid.edge(a, cell) + 0.5 * self.grid.cell[a];
                edge += whole_periods(m.at(now)[a] - middle, self.period[a]);
            }
            consider((edge - p[a]) / v, Kind::Cell { axis, up }, NONE);
        }
        self.event[i] = event;
        self.queue.set(i, time);
    }

    /// When falling circle `i` (acceleration `acc` along axis `a`) leaves its cell along `a`,
    /// and whether upwards: none through the outer edges of a walled box, nor where one cell
    /// spans a period. Times count from its reference time, but the exit is found from where
    /// it is now: crossings do not move the reference point, which may lie cells behind, and a
    /// parabola from there may leave the cell's span before it ever reaches the cell.
    fn cell_exit(&self, i: usize, a: usize, acc: f64) -> Option<(f64, bool)> {
        let m = &self.motion[i];
        let (x, v) = (self.pos_at(i, self.now)[a], self.vel_at(i, self.now)[a]);
        let (cell, last) = if a == 0 {
            (self.cell_x[i] as usize, self.grid.cols - 1)
        } else {
            (self.cell_y[i] as usize, self.grid.rows - 1)
        };
        if last == 0 {
            return None;
        }
        let (mut lo, mut hi) = (self.grid.edge(a, cell), self.grid.edge(a, cell + 1));
        if self.grid.periodic {
            // The cell's image the circle is in now (see `schedule`).
            let middle = lo + 0.5 * self.grid.cell[a];
            let shift = whole_periods(x - middle, self.period[a]);
            (lo, hi) = (lo + shift, hi + shift);
        } else if !self.arena.has_walls() {
            // The outer cells of an open arena reach on without end: a circle beyond the
            // arena stays in its outer cell until it comes back across the inner edge.
            if cell == 0 {
                lo = f64::NEG_INFINITY;
            }
            if cell == last {
                hi = f64::INFINITY;
            }
        }
        let (t, up) = exit_time(x, v, acc, lo, hi)?;
        let outer = !self.grid.periodic && ((up && cell == last) || (!up && cell == 0));
        (!outer).then_some((self.now - m.t_at + t, up))
    }

    pub(super) fn predict_all(&mut self) {
        self.predict_all_until(|| false);
    }

    /// [`EventEngine::predict_all`], asking `stop` every
    /// [`STOP_POLL_CIRCLES`](super::STOP_POLL_CIRCLES) circles whether to give up; whether it
    /// predicted them all.
    ///
    /// When nothing moves ([`EventEngine::is_still`]: a pile asleep, which `swept` builds anew
    /// after something outside touched it), no pair can meet, so no circle looks at its
    /// neighbours: each gets no pair, as looking would have found, and its other events are
    /// asked as always.
    pub(super) fn predict_all_until(&mut self, stop: impl Fn() -> bool) -> bool {
        let still = self.is_still();
        for i in 0..self.len() {
            if i % super::STOP_POLL_CIRCLES == 0 && stop() {
                return false;
            }
            if still {
                self.best_pair[i] = NO_PAIR;
                self.schedule(i);
            } else {
                self.predict(i);
            }
        }
        true
    }
}
