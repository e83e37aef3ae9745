//! The narrow phase for one pair, as plain functions over plain data: the contact normal, the
//! restitution impulse ([`apply_impulse`], the one impulse every solver applies) and, for the
//! discrete solvers, [`resolve_contact`]: positional separation along the normal split by
//! inverse mass, then the impulse if (and only if) the pair is still approaching.

use bevy::math::DVec2;

use crate::base::circle::CircleState;

/// What [`resolve_contact`] did to a pair.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ContactOutcome {
    /// Overlap depth before separation, as a fraction of the smaller radius (0 if apart).
    pub penetration: f64,
    /// Magnitude of the impulse applied (0 if the pair was not approaching). Non-zero means a
    /// collision to count; `(r_a + r_b) · impulse` summed over collisions gives the virial.
    pub impulse: f64,
    /// Unit normal from `a` to `b` (zero if apart).
    pub normal: DVec2,
    /// Speed at which the pair approached along the normal before the impulse (0 if apart or
    /// separating).
    pub normal_speed: f64,
}

/// The restitution of a hit between two surfaces of restitution `a` and `b`: the smaller one
/// (the deader surface decides), so a circle without its own value, which takes the scene's,
/// never makes a pair bouncier than the scene asks. Walls combine with circles the same way.
///
/// ```
/// use moving_circles::kernels::combine_restitution;
///
/// assert_eq!(combine_restitution(1.0, 0.3), 0.3);
/// ```
#[inline]
pub fn combine_restitution(a: f64, b: f64) -> f64 {
    a.min(b)
}

/// The unit contact normal along `d` (from the first circle to the second) and `|d|`.
/// Coincident centres have no direction of their own; they get one from `closing` (the first
/// circle's velocity relative to the second), or `+x` if that is zero too, so no NaN can arise.
#[inline]
pub fn contact_normal(d: DVec2, closing: DVec2) -> (DVec2, f64) {
    let dist = d.length();
    if dist > 0.0 && dist.is_finite() {
        return (d / dist, dist);
    }
    (closing.try_normalize().unwrap_or(DVec2::X), 0.0)
}

/// Applies the restitution impulse `j = -(1 + e)(v_rel · n) / (w_a + w_b)` along the normal `n`
/// (from `a` to `b`) to velocities `va`, `vb` of inverse masses `wa`, `wb`, if the pair
/// approaches and can move. Returns `j`, or `None` if nothing was applied.
///
/// With `restitution = 1` it conserves kinetic energy and momentum exactly (up to rounding).
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::apply_impulse;
///
/// let (mut va, mut vb) = (DVec2::new(1.0, 0.0), DVec2::new(-2.0, 0.0));
/// let j = apply_impulse(DVec2::X, &mut va, &mut vb, 1.0, 1.0, 1.0);
/// assert_eq!(j, Some(3.0));
/// assert_eq!((va, vb), (DVec2::new(-2.0, 0.0), DVec2::new(1.0, 0.0))); // equal masses swap
/// ```
#[inline]
pub fn apply_impulse(
    n: DVec2,
    va: &mut DVec2,
    vb: &mut DVec2,
    wa: f64,
    wb: f64,
    restitution: f64,
) -> Option<f64> {
    let approach = (*vb - *va).dot(n);
    let w = wa + wb;
    if !(approach < 0.0 && w > 0.0) {
        return None;
    }
    let impulse = -(1.0 + restitution) * approach / w;
    *va -= n * (impulse * wa);
    *vb += n * (impulse * wb);
    Some(impulse)
}

/// What one impulse gave the movable circle of a pair whose other circle is immovable (static
/// or kinematic, inverse mass 0): the kinetic energy and momentum it gained. Zero unless
/// exactly one of the two is immovable. `va`, `vb` are the velocities before and after.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::work_by_immovable;
///
/// // A paddle (inverse mass 0) sends a resting unit mass off at 2: it gave it 2 J and 2 N·s.
/// let (work, impulse) =
///     work_by_immovable((0.0, 1.0), (DVec2::X, DVec2::X), (DVec2::ZERO, 2.0 * DVec2::X));
/// assert_eq!((work, impulse), (2.0, 2.0 * DVec2::X));
/// ```
#[inline]
pub fn work_by_immovable(
    inverse_masses: (f64, f64),
    va: (DVec2, DVec2),
    vb: (DVec2, DVec2),
) -> (f64, DVec2) {
    let (w, (before, after)) = match inverse_masses {
        (0.0, w) if w > 0.0 => (w, vb),
        (w, 0.0) if w > 0.0 => (w, va),
        _ => return (0.0, DVec2::ZERO),
    };
    let m = 1.0 / w;
    (
        0.5 * m * (after.length_squared() - before.length_squared()),
        m * (after - before),
    )
}

/// Resolves one pair in place if it overlaps: separates it along the normal (split by inverse
/// mass) and applies `apply_impulse` when the pair approaches. `b` must be the image nearest
/// to `a` on a periodic arena.
///
/// Separation moves positions only, so with `restitution = 1` neither kinetic energy nor
/// momentum changes beyond rounding.
pub fn resolve_contact(
    a: &mut CircleState,
    b: &mut CircleState,
    restitution: f64,
) -> ContactOutcome {
    let reach = a.radius + b.radius;
    if a.position.distance_squared(b.position) >= reach * reach {
        return ContactOutcome::default();
    }
    let (wa, wb) = (a.inv_mass(), b.inv_mass());
    let total_inv_mass = wa + wb;
    let (n, dist) = contact_normal(b.position - a.position, a.velocity - b.velocity);
    let overlap = reach - dist;
    let penetration = overlap / a.radius.min(b.radius);
    if total_inv_mass <= 0.0 {
        // Two immovable circles: nothing can move.
        return ContactOutcome {
            penetration,
            normal: n,
            ..ContactOutcome::default()
        };
    }
    a.position -= n * (overlap * wa / total_inv_mass);
    b.position += n * (overlap * wb / total_inv_mass);
    let approach = (a.velocity - b.velocity).dot(n);
    let impulse = apply_impulse(n, &mut a.velocity, &mut b.velocity, wa, wb, restitution);
    ContactOutcome {
        penetration,
        impulse: impulse.unwrap_or(0.0),
        normal: n,
        normal_speed: if impulse.is_some() { approach } else { 0.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(x: f64, y: f64, vx: f64, vy: f64) -> CircleState {
        CircleState::new(DVec2::new(x, y), DVec2::new(vx, vy), 0.5)
    }

    #[test]
    fn equal_masses_head_on_swap_velocities() {
        let (mut a, mut b) = (body(0.0, 0.0, 1.0, 0.0), body(0.9, 0.0, -2.0, 0.0));
        let out = resolve_contact(&mut a, &mut b, 1.0);
        assert_eq!(out.impulse, 3.0, "j = (1 + e)·|v_rel| / (2/m) = 2·3/2");
        assert_eq!((out.normal, out.normal_speed), (DVec2::X, 3.0));
        assert!((out.penetration - 0.2).abs() < 1e-6);
        assert_eq!(a.velocity, DVec2::new(-2.0, 0.0));
        assert_eq!(b.velocity, DVec2::new(1.0, 0.0));
        assert!((a.position.distance(b.position) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn separating_pairs_are_pushed_apart_but_keep_their_velocities() {
        let (mut a, mut b) = (body(0.0, 0.0, -1.0, 0.0), body(0.9, 0.0, 1.0, 0.0));
        let out = resolve_contact(&mut a, &mut b, 1.0);
        assert_eq!(out.impulse, 0.0);
        assert_eq!(
            (a.velocity, b.velocity),
            (DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0))
        );
        assert!(a.position.distance(b.position) >= 1.0 - 1e-6);
    }

    #[test]
    fn coincident_centres_separate_without_nan() {
        for (va, vb) in [(DVec2::ZERO, DVec2::ZERO), (DVec2::X, -DVec2::X)] {
            let (mut a, mut b) = (body(1.0, 1.0, va.x, va.y), body(1.0, 1.0, vb.x, vb.y));
            resolve_contact(&mut a, &mut b, 1.0);
            assert!(a.position.is_finite() && b.position.is_finite());
            assert!(a.velocity.is_finite() && b.velocity.is_finite());
            assert!((a.position.distance(b.position) - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn an_immovable_circle_does_not_move() {
        let mut wall = body(0.0, 0.0, 0.0, 0.0).with_mass(f64::INFINITY);
        let mut ball = body(0.8, 0.0, -3.0, 0.0);
        resolve_contact(&mut wall, &mut ball, 1.0);
        assert_eq!(wall.position, DVec2::ZERO);
        assert_eq!(wall.velocity, DVec2::ZERO);
        assert_eq!(ball.velocity, DVec2::new(3.0, 0.0));
        assert!((ball.position.x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn two_immovable_circles_get_no_impulse() {
        let (mut va, mut vb) = (DVec2::X, -DVec2::X);
        assert_eq!(
            apply_impulse(DVec2::X, &mut va, &mut vb, 0.0, 0.0, 1.0),
            None
        );
        assert_eq!((va, vb), (DVec2::X, -DVec2::X));
    }
}
