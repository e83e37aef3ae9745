//! Resting and sleeping under gravity: how the event engine avoids inelastic collapse. A
//! falling circle that bounces off a support (an arena wall, a segment wall, an immovable or
//! sleeping circle) so weakly that it would rise less than [`REST_HEIGHT`] of its radius has
//! come to rest on it, if its supports hold it (a floor under it, or two supports on either
//! side of straight down: a groove) and it barely moves along them (slower than a fall of
//! [`WAKE_HEIGHT`] of its radius gives). Then it falls asleep where it is: its velocity zeroed,
//! immovable at rest until woken. On a slope or the side of a circle, where nothing holds it,
//! or sliding along a floor, it slides on, its bounce kept at that height by turning some of
//! its speed along the support into speed off it (its energy unchanged), so its bounces come no
//! faster than that height allows instead of ever faster. A circle all but at rest where
//! nothing holds it (placed at rest on a slope) is given that least bounce to start sliding:
//! the one place energy is added, at most a fall of a thousandth of its radius. A sleeping circle is woken by a hit that approaches faster
//! than a fall of [`WAKE_HEIGHT`] of its radius gives, or by an immovable circle that moves (a
//! kinematic paddle); a softer hit bounces off it as off a static circle. The little a circle
//! still slides at when it falls asleep is lost, as on a rough surface.
//!
//! Collisions of circles that do not rest on anything can collapse too: a row of touching
//! circles pushed sideways against a wall trades ever smaller impulses at one instant. Under
//! gravity a hit within a circle's contact time of its last one is elastic ([`CONTACT_TIME`]),
//! which ends that.
//!
//! Without gravity nothing falls and nothing sleeps. At restitution 1 a bounce never dies
//! down; a circle pressed against a support with no speed at all (a stack placed at rest)
//! sleeps at once, since its bounce is below rounding ([`ROUNDING_HEIGHT`]).

use bevy::math::DVec2;

use super::EventEngine;
use crate::step::boundary::put_back_inside;

/// A bounce that would lift a circle less than this many of its radii is rest.
pub const REST_HEIGHT: f64 = 1e-3;
/// The same at restitution 1, where only a bounce lost in rounding is rest.
pub const ROUNDING_HEIGHT: f64 = 1e-12;
/// A sleeping circle wakes when hit faster than a fall of this many of its radii.
pub const WAKE_HEIGHT: f64 = 1e-2;
/// A circle bouncing its least bounce that has stayed within this many of its radii of one place
/// for [`RESTING_TIME`] rests (the default sleep of the time-stepped solvers, 0.1 radii per
/// second for half a second).
pub const RESTING_DRIFT: f64 = 0.05;
/// See [`RESTING_DRIFT`], in seconds.
pub const RESTING_TIME: f64 = 0.5;
/// A circle's contact time, in units of `√(r/g)` (how long a fall of half its radius takes,
/// about): under gravity a hit within this of the circle's last one is elastic (the TC model of
/// Luding and McNamara), so that a chain of touching circles pushed sideways, where no support
/// holds anything up, cannot collapse into ever faster collisions at one instant, and circles
/// pressed together in a pile as it forms trade a bounded number of hits instead of ever more.
///
/// A lone circle bouncing on a support rests ([`REST_HEIGHT`]) before its bounces come this
/// quickly: a bounce to that height lasts `2·√(2·REST_HEIGHT)·√(r/g)` ≈ 0.09 `√(r/g)`, about
/// nine times this (more than twice, checked below). At `r` = 0.75 m and `g` = 9.81 it is
/// 2.8 ms, a sixth of a 60 Hz frame. A hundredth of `√(r/g)` rather than less: a pile of 2000
/// circles forming makes about five times as many hits at 1e-4 (2.4 million in its first 20 s
/// against 0.50 million, both at rounding overlap and asleep; measured on 2026-12-04,
/// `docs/history.md`).
pub const CONTACT_TIME: f64 = 1e-2;

// A bounce at the rest height lasts more than twice the contact time: `(2·√(2h))² = 8h`
// against `(2·t_c)²`.
const _: () = assert!(4.0 * CONTACT_TIME * CONTACT_TIME < 8.0 * REST_HEIGHT);
/// Hits in a row, each within the contact time of the one before, after which a falling circle
/// is jammed (pressed between supports it cannot leave, trading elastic hits at one instant)
/// and falls asleep where it is.
pub const JAM_HITS: u32 = 8;

impl EventEngine {
    /// The restitution of a hit of `circles` at restitution `e` now: 1 under gravity if any of
    /// them that moves was hit less than its contact time ago ([`CONTACT_TIME`]). Marks those
    /// hit now. One that does not move (immovable, or asleep and not woken by this hit) is what
    /// others land on, not a body in a contact: hits on a peg or a sleeper by different circles
    /// are separate contacts, however close together.
    pub(super) fn contact_time_restitution(&mut self, circles: &[usize], e: f64) -> f64 {
        if self.gravity == DVec2::ZERO {
            return e;
        }
        let g = self.gravity.length();
        let mut elastic = false;
        for &i in circles {
            if self.moving_inv_mass(i) == 0.0 {
                continue;
            }
            let contact = CONTACT_TIME * (self.motion[i].radius / g).sqrt();
            let quick = self.now - self.last_hit[i] < contact;
            self.quick_hits[i] = if quick { self.quick_hits[i] + 1 } else { 0 };
            elastic |= quick;
            self.last_hit[i] = self.now;
        }
        if elastic { 1.0 } else { e }
    }

    /// Puts circle `i` to sleep if it is jammed: [`JAM_HITS`] quick hits in a row, the last at
    /// restitution `e`, without going anywhere (within [`RESTING_DRIFT`] of its radius of one
    /// place; at `e = 1`, where stopping it must lose no more than rounding, all but still:
    /// slower than a fall of [`ROUNDING_HEIGHT`] of its radius gives). Quick hits alone are no
    /// jam: the contact time grows as `√(r/g)`, so under weak gravity every hit of a gas is
    /// quick, and a circle in flight put to sleep takes its energy with it.
    pub(super) fn sleep_if_jammed(&mut self, i: usize, e: f64) {
        if !self.falls[i] || self.quick_hits[i] < JAM_HITS {
            return;
        }
        let jammed = if e < 1.0 {
            self.near_anchor(i)
        } else {
            self.slower_than_a_fall(i, ROUNDING_HEIGHT)
        };
        if jammed {
            self.fall_asleep(i);
        }
    }

    /// Circle `i` sleeps from now: at rest where it is. A centre the clock's rounding left past
    /// an arena wall (a circle too fast for the clock to resolve, crossing metres in its last
    /// tick) is put back inside, as the wall hit that sleeping cancels would have put it.
    fn fall_asleep(&mut self, i: usize) {
        self.asleep[i] = true;
        self.falls[i] = false;
        self.quick_hits[i] = 0;
        self.motion[i].vel = DVec2::ZERO;
        self.stop_turning(i);
        let m = &mut self.motion[i];
        if self.arena.has_walls() && !self.arena.contains(m.pos) {
            put_back_inside(&mut m.pos, m.radius, &self.arena);
            self.relist(i);
        }
    }

    /// Whether circle `i` flies a parabola: movable, awake, under gravity.
    pub(super) fn can_fall(&self, i: usize) -> bool {
        self.gravity != DVec2::ZERO && self.inv_mass[i] > 0.0 && !self.asleep[i]
    }

    /// Circle `i`'s inverse mass in a collision now: none while it sleeps.
    pub(super) fn moving_inv_mass(&self, i: usize) -> f64 {
        if self.asleep[i] {
            0.0
        } else {
            self.inv_mass[i]
        }
    }

    /// Whether sleeping circle `sleeper` wakes when `hitter` approaches it at `approach`.
    pub(super) fn wakes(&self, sleeper: usize, hitter: usize, approach: f64) -> bool {
        let r = self.motion[sleeper].radius;
        let wake = 2.0 * self.gravity.length() * WAKE_HEIGHT * r;
        let pushed = self.inv_mass[hitter] == 0.0 && self.motion[hitter].vel != DVec2::ZERO;
        pushed || approach * approach > wake
    }

    /// Wakes circle `i` (at rest, at its place, now).
    pub(super) fn wake(&mut self, i: usize) {
        self.asleep[i] = false;
        self.falls[i] = self.can_fall(i);
        self.motion[i].t_at = self.now;
    }

    /// After circle `i` bounced off a support along `n` (from the circle towards the support)
    /// with restitution `e`: puts it to sleep if gravity presses it into the support and the
    /// bounce would lift it less than [`REST_HEIGHT`] of its radius ([`ROUNDING_HEIGHT`] at
    /// `e = 1`).
    pub(super) fn rest_on_support(&mut self, i: usize, n: DVec2, e: f64) {
        if !self.falls[i] {
            return;
        }
        let pressed = self.gravity.dot(n);
        if pressed <= 0.0 {
            return;
        }
        let rebound = (-self.motion[i].vel.dot(n)).max(0.0);
        let height = if e < 1.0 {
            REST_HEIGHT
        } else {
            ROUNDING_HEIGHT
        };
        let least = (2.0 * pressed * height * self.motion[i].radius).sqrt();
        if rebound >= least {
            return;
        }
        let v = self.motion[i].vel;
        let along = v - n * v.dot(n);
        // Sleep only when held and all but still; a circle sliding fast along a floor, or held
        // by nothing, slides on.
        let still = self.slower_than_a_fall(i, WAKE_HEIGHT);
        if (still && self.held(i)) || self.stayed(i) {
            self.fall_asleep(i);
        } else if v.length() > least && along != DVec2::ZERO {
            // Sliding off: off the support at the least bounce, the rest of its speed along it.
            let slide = (v.length_squared() - least * least).sqrt();
            self.motion[i].vel = along.normalize() * slide - n * least;
        } else {
            // All but at rest where nothing holds it (placed on a slope): it starts sliding
            // with the least bounce.
            self.motion[i].vel = along - n * least;
        }
    }

    /// Whether circle `i` moves slower than a fall of `height` of its radius gives.
    fn slower_than_a_fall(&self, i: usize, height: f64) -> bool {
        let m = &self.motion[i];
        m.vel.length_squared() < 2.0 * self.gravity.length() * height * m.radius
    }

    /// Whether circle `i`, bouncing its least bounce, has stayed within [`RESTING_DRIFT`] of its
    /// radius of one place for [`RESTING_TIME`]: held by circles that are awake themselves (two
    /// leaning on each other), it rests all the same.
    fn stayed(&mut self, i: usize) -> bool {
        self.near_anchor(i) && self.now - self.anchor[i].1 >= RESTING_TIME
    }

    /// Whether circle `i` is within [`RESTING_DRIFT`] of its radius of its anchor, the place it
    /// has stayed near since the anchor's time; if not, the anchor moves to where it is now.
    fn near_anchor(&mut self, i: usize) -> bool {
        let (p, r) = (self.motion[i].pos, self.motion[i].radius);
        if self.offset(self.anchor[i].0, p).length() > RESTING_DRIFT * r {
            self.anchor[i] = (p, self.now);
            return false;
        }
        true
    }

    /// Whether circle `i`'s supports hold it against gravity: a support right under it, or two
    /// on either side of straight down (one may be a wall beside it), among the walls, segment
    /// walls and circles at rest that it meets and touches (to within ten rest heights' gap).
    fn held(&self, i: usize) -> bool {
        let up = -self.gravity.normalize_or_zero();
        let (p, r) = (self.motion[i].pos, self.motion[i].radius);
        let gap = 10.0 * REST_HEIGHT * r;
        let mut normals: Vec<DVec2> = Vec::new();
        if self.arena.has_walls() {
            for axis in 0..2 {
                let mut n = DVec2::ZERO;
                n[axis] = 1.0;
                if p[axis] - r - self.arena.min[axis] <= gap {
                    normals.push(n);
                }
                if self.arena.max[axis] - r - p[axis] <= gap {
                    normals.push(-n);
                }
            }
        }
        for &k in self.segment_cells.in_cell(self.cell_index(i)) {
            let (_, out, distance) = self.segments[k as usize].contact(p, self.motion[i].vel);
            if distance - r <= gap {
                normals.push(out);
            }
        }
        for j in self.near(i) {
            let resting =
                self.asleep[j] || (self.inv_mass[j] == 0.0 && self.velocity(j) == DVec2::ZERO);
            if j == i || !resting || !self.meets(i, j) {
                continue;
            }
            let d = self.offset(self.position(j), p);
            let distance = d.length();
            if distance - r - self.motion[j].radius <= gap && distance > 0.0 {
                normals.push(d / distance);
            }
        }
        let flat = normals.iter().any(|m| m.dot(up) >= 1.0 - 1e-9);
        let side = |m: &DVec2| m.perp_dot(up);
        // Straight up between two normals (a wall's, square to it, counts: a circle pressed by
        // the one below into a wall is held).
        let cradled = normals.iter().any(|a| {
            a.dot(up) >= 0.0
                && side(a) > 0.0
                && normals
                    .iter()
                    .any(|b| b.dot(up) >= 0.0 && side(b) < 0.0 && a.dot(up) + b.dot(up) > 0.0)
        });
        flat || cradled
    }
}
