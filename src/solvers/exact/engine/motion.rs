//! Where a circle is on its course: in a straight line, or on a parabola when it falls, from
//! its reference point (`pos_at`, `vel_at`), moved there only where its course changes
//! (`advance_circle`); where a pair is across the periodic arena (the image a displacement is
//! nearest in, and the `frame` of now and the period that a pair's time is worked out in); and
//! the fallback that moves every circle along its course without events when a step's budget
//! runs out (`drift_to`).

use bevy::math::DVec2;

use super::EventEngine;
use super::events::Frame;
use crate::base::arena::minimum_image;
use crate::step::boundary::reflect_off_walls;

impl EventEngine {
    /// How many times the smallest circle that moves falls its own radius (`√(r/g)`) in
    /// `span` seconds: under strong gravity, about how often each circle bounces (0 without
    /// gravity or moving circles).
    pub fn falls_in(&self, span: f64) -> f64 {
        if self.gravity == DVec2::ZERO {
            return 0.0;
        }
        let least = self
            .motion
            .iter()
            .zip(&self.inv_mass)
            .filter(|(_, w)| **w > 0.0)
            .map(|(m, _)| m.radius)
            .reduce(f64::min);
        least.map_or(0.0, |r| span * (self.gravity.length() / r).sqrt())
    }

    /// Where circle `i` is at time `t` on its current course (not wrapped).
    #[inline]
    pub(super) fn pos_at(&self, i: usize, t: f64) -> DVec2 {
        let m = &self.motion[i];
        if self.falls[i] {
            let tau = t - m.t_at;
            m.pos + m.vel * tau + 0.5 * self.gravity * (tau * tau)
        } else {
            m.at(t)
        }
    }

    /// Circle `i`'s velocity at time `t` on its current course.
    #[inline]
    pub(super) fn vel_at(&self, i: usize, t: f64) -> DVec2 {
        let m = &self.motion[i];
        if self.falls[i] {
            m.vel + self.gravity * (t - m.t_at)
        } else {
            m.vel
        }
    }

    /// Circle `i`'s acceleration on its current course.
    #[inline]
    pub(super) fn acceleration(&self, i: usize) -> DVec2 {
        if self.falls[i] {
            self.gravity
        } else {
            DVec2::ZERO
        }
    }

    /// Moves every circle in a straight line to `t` without processing events (walls fold the
    /// motion back inside, periodic edges wrap, an open arena lets it go), then predicts afresh. The fallback when a step's
    /// event budget runs out: collisions skipped here show up as overlapping, approaching pairs,
    /// which collide at once on the next advance.
    pub fn drift_to(&mut self, t: f64) {
        self.fly_unpredicted_to(t);
        self.relink_all();
        self.predict_all();
    }

    /// [`EventEngine::drift_to`] without the cells and predictions that make the engine
    /// go on: what is left is read ([`EventEngine::position`], [`EventEngine::velocity`]) and
    /// thrown away; advanced again, it would follow stale events. A stopped run's last step ends so, in O(N) however many circles there are,
    /// where predicting millions of circles again takes seconds.
    pub(crate) fn fly_unpredicted_to(&mut self, t: f64) {
        let arena = self.arena;
        let scale = 1.0 + self.growth * t;
        for i in 0..self.len() {
            let (mut p, mut v) = (self.pos_at(i, t), self.vel_at(i, t));
            let m = &mut self.motion[i];
            if arena.is_periodic() {
                p = arena.wrap(p);
            } else if arena.has_walls() {
                let r = m.radius * scale;
                reflect_off_walls(&mut p, &mut v, r, &arena, self.wall_restitution);
            }
            (m.pos, m.vel, m.t_at) = (p, v, t);
            self.counter[i] += 1;
        }
        self.now = t;
    }

    /// Moves circle `i`'s reference point to time `t`, where its course is about to change
    /// (inside a periodic arena). Crossings never move it: only events that every grid of cells
    /// shares do, so the trajectories do not depend on the grid.
    pub(super) fn advance_circle(&mut self, i: usize, t: f64) {
        let (p, v) = (self.pos_at(i, t), self.vel_at(i, t));
        self.motion[i].pos = self.inside(p);
        self.motion[i].vel = v;
        self.motion[i].t_at = t;
    }

    /// `p`, or on a periodic arena its image in `[min, max)`.
    #[inline]
    pub(super) fn inside(&self, p: DVec2) -> DVec2 {
        let arena = &self.arena;
        if self.grid.periodic && !(p.cmpge(arena.min).all() && p.cmplt(arena.max).all()) {
            arena.wrap(p)
        } else {
            p
        }
    }

    /// The displacement from `a` to `b` (minimum image on a periodic arena).
    #[inline]
    pub(super) fn offset(&self, a: DVec2, b: DVec2) -> DVec2 {
        if self.grid.periodic {
            minimum_image(b - a, self.period)
        } else {
            b - a
        }
    }

    /// How many whole periods along each axis the displacement `d` is beyond its minimum image
    /// (`d` minus that many periods is within half a period).
    #[inline]
    pub(super) fn nearest_image(&self, d: DVec2) -> DVec2 {
        let period = self.period;
        DVec2::new(whole_images(d.x, period.x), whole_images(d.y, period.y))
    }

    /// What a pair's time is worked out in: now, and the period when the arena wraps.
    #[inline]
    pub(super) fn frame(&self) -> Frame {
        Frame {
            now: self.now,
            period: self.grid.periodic.then_some(self.period),
        }
    }
}

/// How many whole periods `d` is beyond its minimum image (`d` minus that many periods is
/// within half a period).
#[inline]
fn whole_images(d: f64, period: f64) -> f64 {
    if d.abs() > 0.5 * period {
        (d / period).round()
    } else {
        0.0
    }
}

/// The whole periods in `d` beyond its minimum image, as a length.
#[inline]
pub(super) fn whole_periods(d: f64, period: f64) -> f64 {
    period * whole_images(d, period)
}
