//! Friction and rolling resistance in the `soft` step, as Box2D v3 solves them: each contact's
//! tangent row (Coulomb: the push along the surface at most μ times the push along the normal,
//! which stops sliding when it can and lets the contact slip when it cannot) and its rolling
//! row (the two circles' relative turning resisted by at most a torque of the rolling
//! resistance times the normal push times the radius). Both are warm started like the normal
//! push and solved after it in every pass; a contact without friction skips them, so a
//! frictionless scene steps exactly as it would without this file.
//!
//! Along a contact's normal `n` (from `a` to the other side) the tangent is `t = n⊥`, and the
//! contact point sits `r_a` from `a`'s centre along `n` and `r_b` from `b`'s against it, so
//! the other side's surface slides past `a`'s at `v_t = (v_b − v_a)·t − ω_b r_b − ω_a r_a`.

use bevy::math::DVec2;

use super::bodies::Bodies;
use super::contacts::{Constraint, TurningRow};
use crate::base::grid::NONE;

/// The tangent of normal `n`: `n` turned a quarter turn counter-clockwise.
#[inline]
pub fn tangent(n: DVec2) -> DVec2 {
    DVec2::new(-n.y, n.x)
}

/// How fast the other side of contact `c` (with row `row`) slides past `a` along the tangent,
/// and the two sides' angular velocities.
#[inline]
fn sliding(bodies: &Bodies, c: &Constraint, row: &TurningRow) -> (f64, f64, f64) {
    let a = c.a as usize;
    let (ra, rb) = row.lever;
    let t = tangent(c.normal);
    let wa = bodies.angular_velocity[a];
    let (vb, wb) = if c.b == NONE {
        (DVec2::ZERO, 0.0)
    } else {
        let b = c.b as usize;
        (bodies.velocity[b], bodies.angular_velocity[b])
    };
    let vt = (vb - bodies.velocity[a]).dot(t) - wb * rb - wa * ra;
    (vt, wa, wb)
}

/// Applies impulse `j` along contact `c`'s tangent (to `b`, and against it to `a`) and the
/// torque impulse `k` that turns `b` by `+k` and `a` by `−k` (through their inverse inertias).
/// Returns the work an immovable side did on the other through the tangent impulse, and the
/// momentum it gave.
#[inline]
pub fn apply_turning(
    bodies: &mut Bodies,
    (c, row): (&Constraint, &TurningRow),
    j: f64,
    k: f64,
) -> (f64, DVec2) {
    let (wa, wb) = c.inv_mass;
    let (ia, ib) = row.inv_inertia;
    let (ra, rb) = row.lever;
    let t = tangent(c.normal);
    let p = t * j;
    let a = c.a as usize;
    let mut work = (0.0, DVec2::ZERO);
    if c.b != NONE {
        let b = c.b as usize;
        if wa == 0.0 || wb == 0.0 {
            // The immovable side's surface velocity at the contact times what it gave, and its
            // turning times the torque it gave.
            work = if wa == 0.0 {
                let spin = bodies.angular_velocity[a];
                let surface = bodies.velocity[a] + t * (spin * ra);
                (p.dot(surface) + k * spin, p)
            } else {
                let spin = bodies.angular_velocity[b];
                let surface = bodies.velocity[b] - t * (spin * rb);
                (-p.dot(surface) - k * spin, -p)
            };
        }
        bodies.velocity[b] += p * wb;
        bodies.angular_velocity[b] += ib * (k - rb * j);
    }
    bodies.velocity[a] -= p * wa;
    bodies.angular_velocity[a] -= ia * (k + ra * j);
    work
}

/// Applies the tangent and rolling impulses of contact `c`'s row from the last substep (or
/// step) again.
#[inline]
pub fn warm_start_turning(bodies: &mut Bodies, c: &Constraint, row: &TurningRow) -> (f64, DVec2) {
    if row.tangent_impulse == 0.0 && row.rolling_impulse == 0.0 {
        return (0.0, DVec2::ZERO);
    }
    apply_turning(bodies, (c, row), row.tangent_impulse, row.rolling_impulse)
}

/// Solves contact `c`'s tangent row (stop the sliding, within μ times the normal push the
/// contact holds now) and then its rolling row (stop the relative turning, within the rolling
/// resistance's torque). Returns the work an immovable side did through them, and the
/// momentum it gave.
#[inline]
pub fn solve_turning(bodies: &mut Bodies, c: &Constraint, row: &mut TurningRow) -> (f64, DVec2) {
    let (vt, wa, wb) = sliding(bodies, c, row);
    let (most, most_rolling) = row.bounds(c.impulse);
    let total = (row.tangent_impulse - row.tangent_mass * vt).clamp(-most, most);
    let j = total - row.tangent_impulse;
    row.tangent_impulse = total;
    let mut k = 0.0;
    if row.rolling > 0.0 {
        // The tangent impulse just found turns both sides: roll against what it leaves.
        let (ia, ib) = row.inv_inertia;
        let (ra, rb) = row.lever;
        let turning = (wb - ib * rb * j) - (wa - ia * ra * j);
        let total =
            (row.rolling_impulse - row.rolling_mass * turning).clamp(-most_rolling, most_rolling);
        k = total - row.rolling_impulse;
        row.rolling_impulse = total;
    }
    apply_turning(bodies, (c, row), j, k)
}

/// Every circle turned by its angular velocity over `h` seconds, its rotation kept in `[-π, π]`.
pub fn turn(bodies: &mut Bodies, h: f64) {
    for (angle, &w) in bodies.rotation.iter_mut().zip(&bodies.angular_velocity) {
        if w != 0.0 {
            *angle = crate::base::components::Rotation(*angle).turned(w * h).0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::hits::{ArenaWall, Wall};
    use crate::solvers::soft::bodies::Softness;
    use crate::solvers::soft::contacts::Partner;

    /// A disc of unit mass and radius resting on a floor below it, moving at `v` and turning
    /// at `w`, with friction `mu` and a normal push of 1 held.
    fn on_floor(v: f64, w: f64, mu: f64) -> (Bodies, Constraint, TurningRow) {
        let mut bodies = Bodies::default();
        bodies.push(1, (DVec2::ZERO, DVec2::new(v, 0.0)), 1.0, 1.0);
        bodies.start_turning();
        bodies.turning(0, (w, 0.0), None);
        let c = Constraint {
            a: 0,
            b: NONE,
            partner: Partner::Wall(Wall::Arena(ArenaWall::Bottom)),
            normal: DVec2::NEG_Y,
            anchor: DVec2::new(0.0, -1.0),
            reach: 1.0,
            inv_mass: (1.0, 0.0),
            normal_mass: 1.0,
            soft: Softness::RIGID,
            restitution: 0.0,
            threshold: 0.0,
            push: 1.0,
            relative_velocity: 0.0,
            impulse: 1.0,
            total_impulse: 1.0,
            approach: 0.0,
            was_touching: true,
            pressing: true,
            turn: 0,
        };
        let row = TurningRow {
            friction: mu,
            rolling: 0.0,
            lever: (1.0, 0.0),
            inv_inertia: (2.0, 0.0),
            tangent_mass: 1.0 / 3.0,
            rolling_mass: 0.5,
            tangent_impulse: 0.0,
            rolling_impulse: 0.0,
        };
        (bodies, c, row)
    }

    #[test]
    fn enough_friction_makes_a_sliding_disc_roll_and_keeps_two_thirds_of_its_speed() {
        // A uniform disc sliding at 3 with no spin rolls, after the friction's one impulse,
        // at 2 (momentum about the contact point is kept: m v r = (m + I / r²) v').
        let (mut bodies, c, mut row) = on_floor(3.0, 0.0, 10.0);
        solve_turning(&mut bodies, &c, &mut row);
        let (v, w) = (bodies.velocity[0].x, bodies.angular_velocity[0]);
        assert!((v - 2.0).abs() < 1e-12, "{v}");
        // Rolling to the right on a floor below turns clockwise: v = −ω r.
        assert!((w + 2.0).abs() < 1e-12, "{w}");
        assert!(sliding(&bodies, &c, &row).0.abs() < 1e-12);
    }

    #[test]
    fn too_little_friction_only_slows_the_slide_by_mu_times_the_push() {
        let (mut bodies, c, mut row) = on_floor(3.0, 0.0, 0.25);
        solve_turning(&mut bodies, &c, &mut row);
        assert!((bodies.velocity[0].x - 2.75).abs() < 1e-12);
        assert!((row.tangent_impulse.abs() - 0.25).abs() < 1e-12);
        // And a rolling disc needs no friction at all.
        let (mut bodies, c, mut row) = on_floor(3.0, -3.0, 0.25);
        solve_turning(&mut bodies, &c, &mut row);
        assert_eq!((bodies.velocity[0].x, row.tangent_impulse), (3.0, 0.0));
    }

    #[test]
    fn rolling_resistance_slows_the_turning_within_its_torque() {
        let (mut bodies, c, mut row) = on_floor(3.0, -3.0, 10.0);
        row.rolling = 0.01;
        solve_turning(&mut bodies, &c, &mut row);
        // At most 0.01 of torque impulse: the spin slows by 0.02 (inverse inertia 2).
        assert!((row.rolling_impulse.abs() - 0.01).abs() < 1e-12);
        assert!((bodies.angular_velocity[0] + 2.98).abs() < 1e-12);
        // The next pass: friction makes the disc roll again, so its speed drops too.
        solve_turning(&mut bodies, &c, &mut row);
        let (v, w) = (bodies.velocity[0].x, bodies.angular_velocity[0]);
        assert!(v < 3.0 && (v + w).abs() < 1e-12, "{v} {w}");
    }
}
