//! One `soft` step as plain functions over [`Bodies`], stage by stage as in Box2D v3's soft
//! step: find the contacts and warm start them from the last step ([`find_contacts`],
//! [`ContactCache`]); then per substep integrate velocities (gravity, drag), apply the warm
//! start, solve the contacts with their soft bias (and their friction, [`super::friction`]),
//! integrate positions and rotations and relax (solve again without the bias, so the push-out
//! leaves no velocity behind); once after the substeps, the restitution pass; last, store the
//! impulses for the next step.
//!
//! Contacts are solved one after another in a fixed order (Gauss-Seidel; arena and segment
//! walls first, then pairs in the broad phase's order), so a step is the same on any number of
//! threads.

use bevy::math::DVec2;

use super::bodies::{Bodies, Softness};
use super::cache::ContactCache;
use super::contacts::{
    Constraint, ContactRules, ContactScratch, TurningRow, find_contacts, may_turn, turning_rows,
};
use super::friction::{solve_turning, turn, warm_start_turning};
use super::stats::{SoftStats, count};
use crate::arena::Arena;
use crate::boundary::put_back_inside;
use crate::config::{Combine, SoftConfig};
use crate::grid::NONE;
use crate::hits::HitLog;
use crate::segment::{Segment, SegmentCells};

/// What one `soft` step is asked to do besides moving the circles.
#[derive(Clone, Copy, Debug)]
pub struct SoftParams {
    /// The fixed step, in seconds.
    pub dt: f64,
    /// Substeps per step.
    pub substeps: u32,
    /// Constant acceleration, or zero.
    pub gravity: DVec2,
    /// Linear drag rate (1/s), or zero.
    pub drag: f64,
    /// Restitution between circles, and against walls, for circles without their own.
    pub restitution: (f64, f64),
    /// Whether circles collide with each other.
    pub collisions: bool,
    /// Friction between circles, and against walls, for circles without their own.
    pub friction: (f64, f64),
    /// How two friction coefficients meet.
    pub combine: Combine,
    /// Rolling resistance (dimensionless).
    pub rolling_resistance: f64,
    /// The contacts' tuning.
    pub config: SoftConfig,
}

/// Buffers reused from step to step.
#[derive(Default)]
pub struct SoftScratch {
    contacts: ContactScratch,
    pairs: Vec<Constraint>,
    walls: Vec<Constraint>,
    rows: Vec<TurningRow>,
}

/// Advances `bodies` by one step of `params.dt` in `arena` among `segments` (with the cells
/// that list them), warm started from `cache` and leaving this step's impulses in it. Records
/// each collision and wall hit in `hits` if given (time: the end of the part of the step that
/// resolved it).
///
/// A step in which some circle would travel more than [`MAX_TRAVEL`] of its radius is split
/// into equal parts that each stay within it (at most [`MAX_PARTS`]), each finding its own
/// contacts: contacts are found once per part along normals fixed for it, which only holds
/// while circles move a fraction of their size.
pub fn soft_step(
    bodies: &mut Bodies,
    arena: &Arena,
    segments: (&[Segment], &SegmentCells),
    params: &SoftParams,
    (scratch, cache): (&mut SoftScratch, &mut ContactCache),
    mut hits: Option<&mut HitLog>,
) -> SoftStats {
    let parts = parts_needed(bodies, params);
    let part = SoftParams {
        dt: params.dt / f64::from(parts),
        ..*params
    };
    let mut stats = SoftStats::default();
    for k in 0..parts {
        let start = hits.as_deref().map_or(0, |log| log.circles.len());
        let walls_start = hits.as_deref().map_or(0, |log| log.walls.len());
        let done = soft_part(
            bodies,
            arena,
            segments,
            &part,
            (scratch, cache),
            hits.as_deref_mut(),
        );
        if let Some(log) = hits.as_deref_mut() {
            let offset = f64::from(k) * part.dt;
            log.circles[start..]
                .iter_mut()
                .for_each(|h| h.time += offset);
            log.walls[walls_start..]
                .iter_mut()
                .for_each(|h| h.time += offset);
        }
        stats.add(&done);
    }
    stats
}

/// Travel per part of a step, in radii of the circle, past which a step is split.
pub const MAX_TRAVEL: f64 = 1.0;
/// Most parts a step is split into.
pub const MAX_PARTS: u32 = 64;

/// How many parts a step must be split into so that no movable circle travels more than
/// [`MAX_TRAVEL`] radii in one (at most [`MAX_PARTS`]).
fn parts_needed(bodies: &Bodies, params: &SoftParams) -> u32 {
    let fall = 0.5 * params.gravity.length() * params.dt * params.dt;
    let mut worst = 0.0f64;
    for i in 0..bodies.len() {
        if bodies.inv_mass[i] > 0.0 {
            let travel = bodies.velocity[i].length() * params.dt + fall;
            worst = worst.max(travel / bodies.radius[i]);
        }
    }
    let parts = (worst / MAX_TRAVEL).ceil();
    if parts >= f64::from(MAX_PARTS) {
        MAX_PARTS
    } else if parts >= 1.0 {
        parts as u32
    } else {
        1
    }
}

/// One part of a step: contacts, substeps, restitution, store.
fn soft_part(
    bodies: &mut Bodies,
    arena: &Arena,
    segments: (&[Segment], &SegmentCells),
    params: &SoftParams,
    (scratch, cache): (&mut SoftScratch, &mut ContactCache),
    hits: Option<&mut HitLog>,
) -> SoftStats {
    let substeps = params.substeps.max(1);
    let h = params.dt / f64::from(substeps);
    let inv_h = 1.0 / h;
    // Past a quarter of the substep rate a stiffer spring would not be resolved.
    let hertz = params.config.hertz.min(0.25 * inv_h);
    let zeta = params.config.damping_ratio;
    let rules = ContactRules {
        dt: params.dt,
        gravity: params.gravity,
        restitution: params.restitution,
        soft: (
            Softness::new(hertz, zeta, h),
            Softness::new(2.0 * hertz, zeta, h),
        ),
        push_speed: params.config.push_speed,
        threshold: params.config.restitution_threshold,
        collisions: params.collisions,
        friction: params.friction,
        combine: params.combine,
        rolling_resistance: params.rolling_resistance,
    };
    let SoftScratch {
        contacts,
        pairs,
        walls,
        rows,
    } = scratch;
    find_contacts(bodies, arena, segments, &rules, contacts, (pairs, walls));
    rows.clear();
    if may_turn(bodies, &rules) {
        bodies.start_turning();
        turning_rows(
            bodies,
            &rules,
            walls.iter_mut().chain(pairs.iter_mut()),
            rows,
        );
    }
    cache.warm_start(&bodies.id, walls, rows);
    cache.warm_start(&bodies.id, pairs, rows);
    let mut work = Work::default();
    let rows_empty = rows.is_empty();
    let (dv, drag) = (params.gravity * h, (-params.drag * h).exp());
    for _ in 0..substeps {
        integrate_velocities(bodies, dv, drag);
        // A step without friction runs its passes without looking for turning rows at all.
        let contacts = (&mut walls[..], &mut pairs[..], &mut rows[..]);
        if rows_empty {
            substep::<false>(bodies, contacts, h, &mut work);
        } else {
            substep::<true>(bodies, contacts, h, &mut work);
        }
    }
    restitution(bodies, (walls, pairs), &mut work);
    cache.store(&bodies.id, walls.iter().chain(pairs.iter()), rows);
    keep_inside(bodies, arena);
    let mut stats = SoftStats {
        immovable_work: work.energy,
        immovable_impulse: work.momentum,
        contacts: pairs.len() + walls.len(),
        ..SoftStats::default()
    };
    count(bodies, (walls, pairs), params.dt, &mut stats, hits);
    stats
}

/// One substep: warm start, solve with the soft push-out, move and turn, relax (the turning
/// rows' part of each pass only with `TURNING`).
fn substep<const TURNING: bool>(
    bodies: &mut Bodies,
    (walls, pairs, rows): (&mut [Constraint], &mut [Constraint], &mut [TurningRow]),
    h: f64,
    work: &mut Work,
) {
    warm_start::<TURNING>(bodies, (walls, pairs), rows, work);
    solve::<TURNING>(bodies, (walls, pairs, rows), 1.0 / h, true, work);
    integrate_positions(bodies, h);
    turn(bodies, h);
    solve::<TURNING>(bodies, (walls, pairs, rows), 1.0 / h, false, work);
}

/// The work immovable circles did on movable ones through their contacts' impulses, and the
/// momentum they gave them.
#[derive(Default)]
struct Work {
    energy: f64,
    momentum: DVec2,
}

impl Work {
    fn add(&mut self, (energy, momentum): (f64, DVec2)) {
        self.energy += energy;
        self.momentum += momentum;
    }
}

/// Gravity and drag for every movable circle, over one substep.
fn integrate_velocities(bodies: &mut Bodies, dv: DVec2, drag: f64) {
    for (v, &w) in bodies.velocity.iter_mut().zip(&bodies.inv_mass) {
        if w > 0.0 {
            *v = *v * drag + dv;
        }
    }
}

/// Every circle along its velocity for one substep (kinematic ones too).
fn integrate_positions(bodies: &mut Bodies, h: f64) {
    for (p, &v) in bodies.position.iter_mut().zip(&bodies.velocity) {
        *p += v * h;
    }
}

/// Applies impulse `j` along contact `c`'s normal (to `a` against it, to `b` along it); `WALL`
/// says whether `c` is a wall's (which has no `b`), so each kind of contact gets its own loop.
#[inline(always)]
fn apply<const WALL: bool>(bodies: &mut Bodies, c: &Constraint, j: f64, work: &mut Work) {
    let (wa, wb) = c.inv_mass;
    let p = c.normal * j;
    let a = c.a as usize;
    if WALL {
        bodies.velocity[a] -= p * wa;
        return;
    }
    let b = c.b as usize;
    if wa == 0.0 || wb == 0.0 {
        // One side is immovable: the work it did is its push times its own velocity along the
        // push (none for a static peg), and the momentum it gave is the push.
        let (pusher, push) = if wa == 0.0 { (a, p) } else { (b, -p) };
        work.energy += push.dot(bodies.velocity[pusher]);
        work.momentum += push;
    }
    bodies.velocity[a] -= p * wa;
    bodies.velocity[b] += p * wb;
}

/// Applies each contact's impulse from the last substep (or step) again: the solve then only
/// corrects it.
fn warm_start<const TURNING: bool>(
    bodies: &mut Bodies,
    (walls, pairs): (&mut [Constraint], &mut [Constraint]),
    rows: &[TurningRow],
    work: &mut Work,
) {
    fn each<const TURNING: bool, const WALL: bool>(
        bodies: &mut Bodies,
        contacts: &mut [Constraint],
        rows: &[TurningRow],
        work: &mut Work,
    ) {
        for c in contacts {
            if c.impulse > 0.0 {
                apply::<WALL>(bodies, c, c.impulse, work);
                c.total_impulse += c.impulse;
            }
            if TURNING && c.turn != NONE {
                work.add(warm_start_turning(bodies, c, &rows[c.turn as usize]));
            }
        }
    }
    each::<TURNING, true>(bodies, walls, rows, work);
    each::<TURNING, false>(bodies, pairs, rows, work);
}

/// The other side's position and velocity for contact `c` (a wall's if `WALL`): a wall's
/// anchor at rest, or `b`'s image.
#[inline(always)]
fn other_side<const WALL: bool>(bodies: &Bodies, c: &Constraint) -> (DVec2, DVec2) {
    if WALL {
        (c.anchor, DVec2::ZERO)
    } else {
        let b = c.b as usize;
        (bodies.position[b] + c.anchor, bodies.velocity[b])
    }
}

/// One pass over the contacts, walls first. With `use_bias` an overlap is pushed out softly
/// (at most at the contact's push speed); without it (the relax pass) only approach is
/// stopped. Either way a gap still open lets the pair approach by as much as closes it within
/// the substep: the speculative part that keeps fast circles from tunnelling.
fn solve<const TURNING: bool>(
    bodies: &mut Bodies,
    (walls, pairs, rows): (&mut [Constraint], &mut [Constraint], &mut [TurningRow]),
    inv_h: f64,
    use_bias: bool,
    work: &mut Work,
) {
    fn each<const TURNING: bool, const WALL: bool>(
        bodies: &mut Bodies,
        (contacts, rows): (&mut [Constraint], &mut [TurningRow]),
        inv_h: f64,
        use_bias: bool,
        work: &mut Work,
    ) {
        for c in contacts {
            let a = c.a as usize;
            let (pb, vb) = other_side::<WALL>(bodies, c);
            let s = c.separation(bodies.position[a], pb);
            let (bias, soft) = if s > 0.0 {
                (s * inv_h, Softness::RIGID)
            } else if use_bias {
                ((c.soft.bias_rate * s).max(-c.push), c.soft)
            } else {
                (0.0, Softness::RIGID)
            };
            let vn = (vb - bodies.velocity[a]).dot(c.normal);
            c.approach = c.approach.max(-vn);
            let j = -c.normal_mass * soft.mass_scale * (vn + bias) - soft.impulse_scale * c.impulse;
            let total = (c.impulse + j).max(0.0);
            let j = total - c.impulse;
            c.impulse = total;
            c.total_impulse += j;
            apply::<WALL>(bodies, c, j, work);
            if TURNING && c.turn != NONE {
                work.add(solve_turning(bodies, c, &mut rows[c.turn as usize]));
            }
        }
    }
    each::<TURNING, true>(bodies, (walls, rows), inv_h, use_bias, work);
    each::<TURNING, false>(bodies, (pairs, rows), inv_h, use_bias, work);
}

/// Bounces the contacts that began to push this step (a hit, not a contact that rests from
/// step to step, as rapier does) faster than their threshold: the normal velocity after the
/// step is set to `-e` times the one before it, never pulling. A speculative contact that never
/// closed has nothing to bounce. Bouncing only new contacts is what keeps a packing of
/// touching circles from gaining energy: restitution applied to every contact of a circle,
/// one after another, each aiming at its own approach speed from before the step, pushes the
/// circle harder than any one hit would.
fn restitution(
    bodies: &mut Bodies,
    (walls, pairs): (&mut [Constraint], &mut [Constraint]),
    work: &mut Work,
) {
    fn each<const WALL: bool>(bodies: &mut Bodies, contacts: &mut [Constraint], work: &mut Work) {
        for c in contacts {
            let resting = c.was_touching || c.total_impulse == 0.0;
            if resting || c.restitution == 0.0 || c.relative_velocity > -c.threshold {
                continue;
            }
            let a = c.a as usize;
            let (_, vb) = other_side::<WALL>(bodies, c);
            let vn = (vb - bodies.velocity[a]).dot(c.normal);
            let j = -c.normal_mass * (vn + c.restitution * c.relative_velocity);
            let total = (c.impulse + j).max(0.0);
            let j = total - c.impulse;
            c.impulse = total;
            c.total_impulse += j;
            apply::<WALL>(bodies, c, j, work);
        }
    }
    each::<true>(bodies, walls, work);
    each::<false>(bodies, pairs, work);
}

/// Puts back a centre that a push or a fast step left outside the arena (walls), or wraps it
/// (periodic); an open arena leaves it where it is.
fn keep_inside(bodies: &mut Bodies, arena: &Arena) {
    if arena.is_open() {
        return;
    }
    for (p, &r) in bodies.position.iter_mut().zip(&bodies.radius) {
        if arena.contains(*p) {
            continue;
        }
        if arena.is_periodic() {
            *p = arena.wrap(*p);
        } else {
            put_back_inside(p, r, arena);
        }
    }
}
