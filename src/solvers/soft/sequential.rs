//! Contacts solved one after another (Gauss-Seidel), each pass in the order given: apply an
//! impulse, warm start, solve with or without the soft push-out, bounce. Walls always go this
//! way, and the pairs of a step with friction (with their turning rows, `TURNING`).

use bevy::math::DVec2;

use super::bodies::{Bodies, Softness};
use super::contacts::{Constraint, TurningRow, larger};
use super::friction::{solve_turning, warm_start_turning};
use super::stats::Work;
use crate::base::grid::NONE;

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
pub fn warm_start<const TURNING: bool>(
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
            warm_start_one::<TURNING, WALL>(bodies, c, rows, work);
        }
    }
    each::<TURNING, true>(bodies, walls, rows, work);
    each::<TURNING, false>(bodies, pairs, rows, work);
}

/// [`warm_start`] for one contact.
#[inline(always)]
pub fn warm_start_one<const TURNING: bool, const WALL: bool>(
    bodies: &mut Bodies,
    c: &mut Constraint,
    rows: &[TurningRow],
    work: &mut Work,
) {
    if c.impulse > 0.0 {
        apply::<WALL>(bodies, c, c.impulse, work);
        c.total_impulse += c.impulse;
    }
    if TURNING && c.turn != NONE {
        work.add(warm_start_turning(bodies, c, &rows[c.turn as usize]));
    }
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
pub fn solve<const TURNING: bool>(
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
            solve_one::<TURNING, WALL>(bodies, (c, rows), inv_h, use_bias, work);
        }
    }
    each::<TURNING, true>(bodies, (walls, rows), inv_h, use_bias, work);
    each::<TURNING, false>(bodies, (pairs, rows), inv_h, use_bias, work);
}

/// [`solve`] for one contact (and its turning row in `rows` with `TURNING`).
#[inline(always)]
pub fn solve_one<const TURNING: bool, const WALL: bool>(
    bodies: &mut Bodies,
    (c, rows): (&mut Constraint, &mut [TurningRow]),
    inv_h: f64,
    use_bias: bool,
    work: &mut Work,
) {
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
    c.approach = larger(-vn, c.approach);
    let j = -c.normal_mass * soft.mass_scale * (vn + bias) - soft.impulse_scale * c.impulse;
    let total = larger(c.impulse + j, 0.0);
    let j = total - c.impulse;
    c.impulse = total;
    c.total_impulse += j;
    apply::<WALL>(bodies, c, j, work);
    if TURNING && c.turn != NONE {
        work.add(solve_turning(bodies, c, &mut rows[c.turn as usize]));
    }
}

/// Most passes of [`restitution`] over a step's bouncing contacts.
pub const BOUNCE_PASSES: u32 = 16;

/// Bounces the contacts that began to push this step (a hit, not a contact that still pressed
/// when the last step ended, as rapier does) after approaching faster than their threshold:
/// the normal
/// velocity after the step is set to `-e` times the one it hit with
/// ([`Constraint::relative_velocity`], which holds the fall over the gap where gravity presses
/// a circle on a wall or an immovable circle), never pulling. Without gravity there is no
/// threshold (nothing can rest), so an elastic hit is elastic at any speed. Bouncing contacts
/// that pushed the step before too (Box2D's rule) pumps energy into a jammed packing.
///
/// The bouncing contacts are listed once into `bouncing` (walls', pairs') and passed over
/// until no impulse changes the velocities by more than rounding (at most [`BOUNCE_PASSES`]):
/// a circle hit from two sides in one step meets both targets, where one pass would leave the
/// first of them broken by the second (with one pass, `gas1k.ron` lost 0.82 of its energy in
/// 10 s; with the passes, 0.11). Last, each contact notes whether it still presses
/// ([`Constraint::pressing`]).
pub fn restitution(
    bodies: &mut Bodies,
    (walls, pairs): (&mut [Constraint], &mut [Constraint]),
    bouncing: &mut (Vec<u32>, Vec<u32>),
    work: &mut Work,
) {
    fn select(contacts: &[Constraint], bouncing: &mut Vec<u32>) {
        bouncing.clear();
        let bounces = |c: &Constraint| {
            let new = !c.was_touching && c.total_impulse > 0.0;
            new && c.restitution > 0.0 && c.relative_velocity < -c.threshold
        };
        let each = contacts.iter().enumerate().filter(|(_, c)| bounces(c));
        bouncing.extend(each.map(|(k, _)| k as u32));
    }
    /// One pass; returns the largest change of normal velocity it made, relative to the
    /// target's.
    fn pass<const WALL: bool>(
        bodies: &mut Bodies,
        contacts: &mut [Constraint],
        bouncing: &[u32],
        work: &mut Work,
    ) -> f64 {
        let mut most = 0.0f64;
        for &k in bouncing {
            let c = &mut contacts[k as usize];
            let a = c.a as usize;
            let (_, vb) = other_side::<WALL>(bodies, c);
            let vn = (vb - bodies.velocity[a]).dot(c.normal);
            let target = -c.restitution * c.relative_velocity;
            let j = -c.normal_mass * (vn - target);
            let total = (c.impulse + j).max(0.0);
            let j = total - c.impulse;
            c.impulse = total;
            c.total_impulse += j;
            apply::<WALL>(bodies, c, j, work);
            most = most.max((j / c.normal_mass).abs() / target);
        }
        most
    }
    select(walls, &mut bouncing.0);
    select(pairs, &mut bouncing.1);
    for _ in 0..BOUNCE_PASSES {
        let most = pass::<true>(bodies, walls, &bouncing.0, work).max(pass::<false>(
            bodies,
            pairs,
            &bouncing.1,
            work,
        ));
        if most <= 1e-12 {
            break;
        }
    }
    // A bounce is no push to warm start the next step with: that would send the circle off
    // at twice its speed until the contact's own pass takes it back, and a wall solved in
    // between stops it short of that, which then takes it through the contact.
    for &k in &bouncing.0 {
        walls[k as usize].impulse = 0.0;
    }
    for &k in &bouncing.1 {
        pairs[k as usize].impulse = 0.0;
    }
    mark_pressing::<true>(bodies, walls);
    mark_pressing::<false>(bodies, pairs);
}

/// Sets [`Constraint::pressing`] for `contacts` as the step leaves them: a contact that pushed
/// but whose sides now part faster than its threshold (a bounce, or a push from another
/// contact) is a hit that ended, and the next approach along it is a new hit.
fn mark_pressing<const WALL: bool>(bodies: &Bodies, contacts: &mut [Constraint]) {
    for c in contacts {
        let (_, vb) = other_side::<WALL>(bodies, c);
        let vn = (vb - bodies.velocity[c.a as usize]).dot(c.normal);
        // Without gravity (no threshold) nothing rests: a contact still closing is a hit
        // that a bounce elsewhere drove on, to bounce at the next step.
        let closing = c.threshold == 0.0 && vn < 0.0;
        c.pressing = c.total_impulse > 0.0 && vn <= c.threshold && !closing;
    }
}
