//! The engine as plain data, for checkpoints: everything a restored engine needs to go on
//! exactly as the original would have (the lazy motions, every pending event and its time, the
//! cell lists in their order), and the checks that turn a damaged or forged snapshot into an
//! error instead of a panic. What follows from the circles and the arena (inverse masses, the
//! grid, the queue's blocks and lists) is rebuilt, not stored.

use bevy::math::DVec2;
use serde::{Deserialize, Serialize};

use super::events::{BestPair, Event, EventStats, Kind, Motion, NO_PAIR};
use super::queue::EventQueue;
use super::spin::{Roughness, Spins};
use super::{EventEngine, Layout, cell_width, walls_inside};
use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::grid::{CellMembers, NONE};
use crate::base::segment::Segment;

/// An [`EventEngine`]'s state between two events, as data ([`EventEngine::snapshot`],
/// [`EventEngine::restore`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EngineSnapshot {
    now: f64,
    motion: Vec<Motion>,
    counter: Vec<u32>,
    event: Vec<Event>,
    time: Vec<f64>,
    best_pair: Vec<BestPair>,
    cells: CellMembers,
    cell_x: Vec<u32>,
    cell_y: Vec<u32>,
    stats: EventStats,
    asleep: Vec<bool>,
    last_hit: Vec<f64>,
    quick_hits: Vec<u32>,
    anchor: Vec<(DVec2, f64)>,
    spins: Option<Spins>,
}

impl EventEngine {
    /// The engine's state as data.
    pub fn snapshot(&self) -> EngineSnapshot {
        EngineSnapshot {
            now: self.now,
            motion: self.motion.clone(),
            counter: self.counter.clone(),
            event: self.event.clone(),
            time: self.queue.times(),
            best_pair: self.best_pair.clone(),
            cells: self.cells.clone(),
            cell_x: self.cell_x.clone(),
            cell_y: self.cell_y.clone(),
            stats: self.stats,
            asleep: self.asleep.clone(),
            last_hit: self.last_hit.clone(),
            quick_hits: self.quick_hits.clone(),
            anchor: self.anchor.clone(),
            spins: self.spins.clone(),
        }
    }

    /// The engine `snapshot` was taken of, given the same `circles` (radii and masses; their
    /// positions, velocities and turning are the snapshot's), arena, restitutions, gravity,
    /// roughness and `pairs` (whether circles collide, [`EventEngine::set_pairs`]) it was built
    /// with. Refuses, saying why, a snapshot that does not fit them or is inconsistent in itself.
    #[allow(clippy::too_many_arguments)]
    pub fn restore(
        snapshot: EngineSnapshot,
        circles: &[CircleState],
        arena: &Arena,
        segments: &[Segment],
        (restitution, wall_restitution): (f64, f64),
        gravity: DVec2,
        roughness: Roughness,
        pairs: bool,
    ) -> Result<Self, String> {
        let n = circles.len();
        let s = snapshot;
        check_turns(s.spins.as_ref(), roughness, (circles, s.now))?;
        let lengths = [
            s.motion.len(),
            s.counter.len(),
            s.event.len(),
            s.time.len(),
            s.best_pair.len(),
            s.cell_x.len(),
            s.cell_y.len(),
            s.asleep.len(),
            s.last_hit.len(),
            s.quick_hits.len(),
            s.anchor.len(),
        ];
        if lengths.iter().any(|&l| l != n) {
            return Err(format!(
                "engine state for {lengths:?} circles, expected {n}"
            ));
        }
        if !s.now.is_finite() {
            return Err(format!("engine clock {} is not finite", s.now));
        }
        // What the engine has added up, from which each step's counts are taken (the fuzz
        // target's find: a wall impulse of NaN made every count after it NaN).
        let st = &s.stats;
        let sums = [st.wall_impulse, st.virial, st.immovable_work];
        if !(sums.iter().all(|x| x.is_finite()) && st.immovable_impulse.is_finite()) {
            return Err("engine state's sums are not finite".to_owned());
        }
        let size = arena.size();
        let width = cell_width(arena, circles, &[]);
        let Layout {
            grid,
            segments,
            segment_cells,
            large,
            reach,
            images_wrap,
        } = walls_inside(arena, circles, segments, width, &[]);
        let partner_ok = |p: u32, i: usize| p == NONE || (p as usize) < n && p as usize != i;
        for (i, c) in circles.iter().enumerate() {
            let m = &s.motion[i];
            // A falling circle's velocity now is its reference velocity plus what gravity
            // gave it since; a sleeper is at rest.
            let falls = gravity != DVec2::ZERO && c.inv_mass() > 0.0 && !s.asleep[i];
            let velocity = if falls {
                m.vel + gravity * (s.now - m.t_at)
            } else {
                m.vel
            };
            let fits = m.pos.is_finite()
                && m.vel.is_finite()
                && m.t_at.is_finite()
                && m.t_at <= s.now
                && !s.last_hit[i].is_nan()
                && !s.anchor[i].0.is_nan()
                && s.anchor[i].1.is_finite()
                && s.last_hit[i] <= s.now
                && m.radius == c.radius
                && velocity == c.velocity
                && !(s.asleep[i] && (m.vel != DVec2::ZERO || c.inv_mass() == 0.0));
            let event = s.event[i];
            let kind_ok = match event.kind {
                Kind::Idle => s.time[i] == f64::INFINITY,
                Kind::Pair => event.partner != NONE && partner_ok(event.partner, i),
                Kind::Wall { axis } | Kind::Cell { axis, .. } => axis < 2,
                Kind::Segment => (event.partner as usize) < segments.len(),
            };
            // A pending event lies ahead, at a finite time: the clock only ever advances to the
            // soonest one.
            let pending_ok =
                event.kind == Kind::Idle || (s.time[i].is_finite() && s.time[i] >= s.now);
            // A circle in the cell lists sits in its cell, or across an edge by rounding.
            let (x, y) = grid.cell_of(c.position);
            let near = |listed: u32, at: usize, count: usize| {
                let apart = (listed as usize).abs_diff(at);
                apart <= 1 || (grid.periodic && apart + 1 >= count)
            };
            let placed_ok = large.contains(&(i as u32))
                || (near(s.cell_x[i], x, grid.cols) && near(s.cell_y[i], y, grid.rows));
            let best = s.best_pair[i];
            if !fits
                || !kind_ok
                || !pending_ok
                || !placed_ok
                || s.time[i].is_nan()
                || best.time.is_nan()
                || !partner_ok(best.partner, i)
                || s.cell_x[i] as usize >= grid.cols
                || s.cell_y[i] as usize >= grid.rows
            {
                return Err(format!("engine state of circle {i} is inconsistent"));
            }
        }
        // Large circles are in no cell list.
        let cell_of = |i: usize| {
            let cell = grid.index(s.cell_x[i] as usize, s.cell_y[i] as usize);
            (!large.contains(&(i as u32))).then_some(cell)
        };
        s.cells.check(grid.len(), n, cell_of)?;
        let inv_mass: Vec<f64> = circles.iter().map(CircleState::inv_mass).collect();
        let falls = (0..n)
            .map(|i| gravity != DVec2::ZERO && inv_mass[i] > 0.0 && !s.asleep[i])
            .collect();
        let stored = (s.event.clone(), s.time.clone());
        let mut engine = Self {
            arena: *arena,
            period: size,
            restitution,
            wall_restitution,
            now: s.now,
            motion: s.motion,
            inv_mass,
            counter: s.counter,
            event: s.event,
            best_pair: s.best_pair,
            queue: EventQueue::with_times(&s.time),
            grid,
            cells: s.cells,
            cell_x: s.cell_x,
            cell_y: s.cell_y,
            stats: s.stats,
            segments,
            segment_cells,
            own_restitution: Vec::new(),
            layers: Vec::new(),
            pairs,
            hits: None,
            growth: 0.0,
            large,
            reach,
            images_wrap,
            gravity,
            falls,
            asleep: s.asleep,
            last_hit: s.last_hit,
            quick_hits: s.quick_hits,
            anchor: s.anchor,
            spins: s.spins,
            #[cfg(target_arch = "x86_64")]
            batch: None,
        };
        engine.check_pending(&stored.0, &stored.1)?;
        engine.check_best_pairs()?;
        match pairs {
            true => engine.check_no_pair_missed()?,
            false => engine.check_no_pair_predicted()?,
        }
        Ok(engine)
    }

    /// Whether each circle's best pair, where its partner has not changed course since, is the
    /// collision their two courses give, bit for bit: looked at again through the image they
    /// were looked at through (on a periodic arena one within two periods of the nearest now,
    /// as they may have flown far since), it comes out at the same time. A time forged later
    /// would let the pair pass into each other (the checkpoint fuzz target's find, a time put
    /// off by 4 %: an overlap of a third of a radius); a pair whose partner changed course
    /// since is looked at again when its time comes.
    fn check_best_pairs(&self) -> Result<(), String> {
        let shifts = if self.grid.periodic { -2..=2 } else { 0..=0 };
        let images = shifts
            .clone()
            .flat_map(|x| shifts.clone().map(move |y| DVec2::new(x as f64, y as f64)));
        for i in 0..self.len() {
            let stored = self.best_pair[i];
            let j = stored.partner as usize;
            if stored.partner == NONE || stored.partner_count != self.counter[j] {
                continue;
            }
            let found = images.clone().any(|k| {
                let image = |d: DVec2| self.nearest_image(d) + k;
                self.pair_alone(i, j, image).time == stored.time
            });
            if !found {
                return Err(format!(
                    "the best pair of circle {i} is not the collision its course and circle \
                     {j}'s give"
                ));
            }
        }
        Ok(())
    }

    /// The collision of circles `i` and `j` alone, through the image `image` picks, as a
    /// prediction of `i` would find it with `j` among its neighbours.
    fn pair_alone(&self, i: usize, j: usize, image: impl Fn(DVec2) -> DVec2) -> BestPair {
        let mut best = NO_PAIR;
        if self.gravity != DVec2::ZERO {
            self.look_falling(i, j, image, &mut best);
        } else if self.images_wrap {
            self.look_at::<true>(&self.motion[i], j, image, &mut best);
        } else {
            self.look_at::<false>(&self.motion[i], j, image, &mut best);
        }
        best
    }

    /// Whether no circle has a best pair, where circles do not collide.
    fn check_no_pair_predicted(&self) -> Result<(), String> {
        match (0..self.len()).find(|&i| self.best_pair[i].partner != NONE) {
            Some(i) => Err(format!(
                "circle {i} has a best pair, where circles do not collide"
            )),
            None => Ok(()),
        }
    }

    /// Whether no two neighbours meet before both their best pairs. Each best pair is checked
    /// against its own partner, but a forged one may leave out a sooner collision with another
    /// neighbour, which the engine would then never see (the checkpoint fuzz target's find: two
    /// circles passed into each other by a seventh of a radius two steps after the resume). In
    /// a true state, whichever of the two last changed course, or crossed into the other's
    /// neighbourhood, looked at the other then, and its best pair has come no later since.
    fn check_no_pair_missed(&self) -> Result<(), String> {
        let best_time = |i: usize| self.best_pair[i].time;
        let nearest = |d: DVec2| self.nearest_image(d);
        for i in 0..self.len() {
            if self.large_reach(i).is_some() {
                continue; // its pairs are looked at from the other side, large ones aside
            }
            let missed = |j: usize| {
                let best = self.pair_alone(i, j, nearest);
                best.partner != NONE && best.time < best_time(i).min(best_time(j))
            };
            if let Some(j) = self.near(i).filter(|&j| j != i).find(|&j| missed(j)) {
                return Err(format!(
                    "circles {i} and {j} meet sooner than either one's best pair"
                ));
            }
        }
        Ok(())
    }

    /// Whether each circle's pending event is the one its own state schedules: its best pair,
    /// or else the soonest wall, segment wall or cell edge on its course. Scheduling depends
    /// only on what the snapshot holds, so a true snapshot passes bit for bit, with one
    /// exception: a falling circle's cell exit is found from where it is now (see
    /// `cell_exit`), so one scheduled at an earlier event may differ by rounding, and it must
    /// only not be put off past the exit found now. An event forged later than a wall or an
    /// edge would let the circle out of its cell or the arena.
    fn check_pending(&mut self, event: &[Event], time: &[f64]) -> Result<(), String> {
        for i in 0..self.len() {
            self.schedule(i);
        }
        let again = self.queue.times();
        let consistent = |i: usize| {
            let (stored, found) = (time[i], again[i]);
            if self.falls[i] && matches!(event[i].kind, Kind::Cell { .. }) {
                stored <= found + FALLING_EXIT_ROUNDING * found.abs().max(1.0)
            } else {
                event[i] == self.event[i] && stored == found
            }
        };
        match (0..self.len()).find(|&i| !consistent(i)) {
            Some(i) => Err(format!(
                "the pending event of circle {i} is not the one its state schedules"
            )),
            None => Ok(()),
        }
    }
}

/// Whether a snapshot's turning fits the `roughness` the engine is restored with, and its
/// `circles` at time `now`: none when smooth; when rough, one finite turn per circle, not
/// taken after `now`, with its angle in `[-π, π]`, giving each circle its spin and rotation;
/// no own moments of inertia, or one per circle, none NaN.
fn check_turns(
    spins: Option<&Spins>,
    roughness: Roughness,
    (circles, now): (&[CircleState], f64),
) -> Result<(), String> {
    let Some(spins) = spins else {
        return match roughness.is_smooth() {
            true => Ok(()),
            false => Err("engine state is smooth, the effects rough".to_owned()),
        };
    };
    if spins.roughness != roughness {
        return Err("engine state's roughness differs from the effects'".to_owned());
    }
    if spins.turn.len() != circles.len() {
        return Err(format!(
            "engine state turns {} circles, expected {}",
            spins.turn.len(),
            circles.len()
        ));
    }
    let own = &spins.own_inertia;
    if !(own.is_empty() || own.len() == circles.len()) || own.iter().flatten().any(|i| i.is_nan()) {
        return Err("engine state's moments of inertia do not fit the circles".to_owned());
    }
    let half_turn = -std::f64::consts::PI..=std::f64::consts::PI;
    for (i, (turn, c)) in spins.turn.iter().zip(circles).enumerate() {
        let fits = turn.spin.is_finite()
            && half_turn.contains(&turn.angle)
            && turn.t_at.is_finite()
            && turn.t_at <= now
            && turn.spin == c.angular_velocity
            && turn.angle_at(now) == c.rotation;
        if !fits {
            return Err(format!(
                "engine state of circle {i} turns it otherwise than the circle"
            ));
        }
    }
    Ok(())
}

/// How much later than the cell exit found now, relative to the time, a falling circle's
/// stored exit may be: its roots, found from another point of the same parabola, differ by
/// rounding, most near the parabola's top, where the root is double.
const FALLING_EXIT_ROUNDING: f64 = 1e-6;

#[cfg(test)]
mod tests;
