//! One `soft` step as plain functions over [`Bodies`], stage by stage as in Box2D v3's soft
//! step: find the contacts and warm start them from the last step ([`find_contacts`],
//! [`ContactCache`]); then per substep integrate velocities (gravity, drag), apply the warm
//! start, solve the contacts with their soft bias (and their friction, [`super::friction`]),
//! integrate positions and rotations and relax (solve again without the bias, so the push-out
//! leaves no velocity behind); once after the substeps, the restitution passes; last, store
//! the impulses for the next step.
//!
//! Contacts are solved in a fixed order (Gauss-Seidel): arena and segment walls first, one
//! after another ([`super::sequential`]); then the pairs, in a step without friction colour by
//! colour, four at a time ([`super::colours`]), in a step with friction one after another in
//! the broad phase's order. So a step is the same on any number of threads.

use bevy::math::DVec2;

use super::bodies::{Bodies, Softness};
use super::cache::ContactCache;
use super::colours::{Colours, Pass, passes};
use super::contacts::{
    Constraint, ContactRules, ContactScratch, TurningRow, find_contacts, may_turn, turning_rows,
};
use super::friction::turn;
use super::sequential::{restitution, solve, solve_one, warm_start, warm_start_one};
use super::stats::{SoftStats, Work, count};
use crate::base::arena::Arena;
use crate::base::config::{Combine, SoftConfig};
use crate::base::hits::HitLog;
use crate::base::segment::{Segment, SegmentCells};
use crate::step::bodies::BodyStore;
use crate::step::boundary::put_back_inside;

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
    colours: Colours,
    bouncing: (Vec<u32>, Vec<u32>),
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
        substep: h,
        gravity: params.gravity,
        restitution: params.restitution,
        soft: (
            Softness::new(hertz, zeta, h),
            Softness::new(2.0 * hertz, zeta, h),
        ),
        push_speed: params.config.push_speed,
        // Without gravity nothing rests, so every approach bounces.
        threshold: if params.gravity == DVec2::ZERO {
            0.0
        } else {
            params.config.restitution_threshold
        },
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
        colours,
        bouncing,
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
    let (dv, drag) = (params.gravity * h, (-params.drag * h).exp());
    if rows.is_empty() {
        // A step without friction solves its pairs colour by colour, four at a time.
        colours.pack(bodies.len(), pairs);
        for _ in 0..substeps {
            integrate_velocities(bodies, dv, drag);
            coloured_substep(bodies, (walls, pairs, colours), h, &mut work);
        }
        colours.unpack(pairs);
    } else {
        for _ in 0..substeps {
            integrate_velocities(bodies, dv, drag);
            let contacts = (&mut walls[..], &mut pairs[..], &mut rows[..]);
            turning_substep(bodies, contacts, h, &mut work);
        }
    }
    restitution(bodies, (walls, pairs), bouncing, &mut work);
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

/// One substep of a step without friction: warm start, solve with the soft push-out, move,
/// relax; in each pass the walls one after another, then the pairs colour by colour (the
/// groups, then the pairs no colour was free for).
fn coloured_substep(
    bodies: &mut Bodies,
    (walls, pairs, colours): (&mut [Constraint], &mut [Constraint], &mut Colours),
    h: f64,
    work: &mut Work,
) {
    let inv_h = 1.0 / h;
    for c in walls.iter_mut() {
        warm_start_one::<false, true>(bodies, c, &[], work);
    }
    colour_pass(bodies, (pairs, colours), Pass::WarmStart, work);
    let mut solve_all = |bodies: &mut Bodies, bias: bool, work: &mut Work| {
        for c in walls.iter_mut() {
            solve_one::<false, true>(bodies, (c, &mut []), inv_h, bias, work);
        }
        colour_pass(bodies, (pairs, colours), Pass::Solve { inv_h, bias }, work);
    };
    solve_all(bodies, true, work);
    integrate_positions(bodies, h);
    solve_all(bodies, false, work);
}

/// One pass over the groups of `colours`, then over the pairs that found no colour.
fn colour_pass(
    bodies: &mut Bodies,
    (pairs, colours): (&mut [Constraint], &mut Colours),
    pass: Pass,
    work: &mut Work,
) {
    let BodyStore {
        position, velocity, ..
    } = &mut bodies.circles;
    passes(colours, position, velocity, pass, work);
    for &k in &colours.rest {
        let c = &mut pairs[k as usize];
        match pass {
            Pass::WarmStart => warm_start_one::<false, false>(bodies, c, &[], work),
            Pass::Solve { inv_h, bias } => {
                solve_one::<false, false>(bodies, (c, &mut []), inv_h, bias, work)
            }
        }
    }
}

/// One substep of a step with friction: warm start, solve with the soft push-out, move and
/// turn, relax, every contact with its turning row, one after another.
fn turning_substep(
    bodies: &mut Bodies,
    (walls, pairs, rows): (&mut [Constraint], &mut [Constraint], &mut [TurningRow]),
    h: f64,
    work: &mut Work,
) {
    warm_start::<true>(bodies, (walls, pairs), rows, work);
    solve::<true>(bodies, (walls, pairs, rows), 1.0 / h, true, work);
    integrate_positions(bodies, h);
    turn(bodies, h);
    solve::<true>(bodies, (walls, pairs, rows), 1.0 / h, false, work);
}

/// Gravity and drag for every movable circle, over one substep.
fn integrate_velocities(bodies: &mut Bodies, dv: DVec2, drag: f64) {
    for (v, &w) in bodies.circles.velocity.iter_mut().zip(&bodies.inv_mass) {
        if w > 0.0 {
            *v = *v * drag + dv;
        }
    }
}

/// Every circle along its velocity for one substep (kinematic ones too).
fn integrate_positions(bodies: &mut Bodies, h: f64) {
    let BodyStore {
        position, velocity, ..
    } = &mut bodies.circles;
    for (p, &v) in position.iter_mut().zip(&*velocity) {
        *p += v * h;
    }
}

/// Puts back a centre that a push or a fast step left outside the arena (walls), or wraps it
/// (periodic); an open arena leaves it where it is.
fn keep_inside(bodies: &mut Bodies, arena: &Arena) {
    if arena.is_open() {
        return;
    }
    let BodyStore {
        position, radius, ..
    } = &mut bodies.circles;
    for (p, &r) in position.iter_mut().zip(&*radius) {
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
