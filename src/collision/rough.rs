//! The rough hit, as a plain function over plain data: at an instantaneous collision, besides
//! the normal impulse, a tangential impulse that reverses the slip of the two surfaces at the
//! contact by a tangential restitution β (Bryan's rough spheres; Huthmann and Zippelius 1997),
//! trading energy between moving and turning. β = −1 is smooth (no tangential impulse),
//! β = +1 perfectly rough (the slip reversed whole: with normal restitution 1 no energy lost),
//! values between lose some. The event engine applies it at each pair and wall event; the
//! contact solver's friction is the Coulomb kind instead (`soft::friction`).

use bevy::math::DVec2;

/// One side of a rough hit: its velocity and spin (changed in place), its radius (the lever
/// from its centre to the contact) and how easily it moves and turns (inverse mass, inverse
/// moment of inertia, both 0 for something immovable such as a wall).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoughSide {
    /// Velocity of the centre.
    pub velocity: DVec2,
    /// Angular velocity, counter-clockwise.
    pub spin: f64,
    /// Distance from the centre to the contact point.
    pub radius: f64,
    /// Inverse mass.
    pub inv_mass: f64,
    /// Inverse moment of inertia about the centre.
    pub inv_inertia: f64,
}

impl RoughSide {
    /// Something that neither moves nor turns (a wall), its surface moving at `velocity`.
    pub fn fixed(velocity: DVec2) -> Self {
        Self {
            velocity,
            ..Self::default()
        }
    }
}

/// Applies the tangential impulse of a rough hit between `a` and `b`, touching along the unit
/// normal `n` (from `a` to `b`), at tangential restitution `beta`, and returns it (along
/// `n.perp()`, on `a`; `b` takes the opposite). The slip of the surfaces at the contact,
/// `g = (v_a − v_b)·t + ω_a r_a + ω_b r_b` with `t = n.perp()`, becomes `−β g`; the impulse acts
/// at the contact point, so momentum and angular momentum about any point are kept, and at
/// β = 1 the energy of moving and turning is too.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::{RoughSide, apply_rough_impulse};
///
/// // A ball sliding right along a floor below it (n points down, into the floor), unit mass
/// // and radius, uniform disc (inverse inertia 2): a perfectly rough floor reverses the slip.
/// let mut ball = RoughSide { velocity: DVec2::X, spin: 0.0, radius: 1.0, inv_mass: 1.0, inv_inertia: 2.0 };
/// let mut floor = RoughSide::fixed(DVec2::ZERO);
/// apply_rough_impulse(-DVec2::Y, &mut ball, &mut floor, 1.0);
/// // The slip (here along +x) goes from 1 to −1: an impulse of −2/3 over 1 + r²·2 = 3.
/// assert!((ball.velocity.x - 1.0 / 3.0).abs() < 1e-15);
/// assert!((ball.spin - -4.0 / 3.0).abs() < 1e-15); // clockwise: it rolls to the right
/// assert!((ball.velocity.x + ball.spin * ball.radius - -1.0).abs() < 1e-15);
/// ```
#[inline]
pub fn apply_rough_impulse(n: DVec2, a: &mut RoughSide, b: &mut RoughSide, beta: f64) -> f64 {
    let t = n.perp();
    let slip = (a.velocity - b.velocity).dot(t) + a.spin * a.radius + b.spin * b.radius;
    let k = a.inv_mass
        + b.inv_mass
        + a.radius * a.radius * a.inv_inertia
        + b.radius * b.radius * b.inv_inertia;
    if !(k > 0.0 && k.is_finite()) || slip == 0.0 || beta == -1.0 {
        return 0.0;
    }
    let j = -(1.0 + beta) * slip / k;
    a.velocity += t * (j * a.inv_mass);
    b.velocity -= t * (j * b.inv_mass);
    a.spin += j * a.radius * a.inv_inertia;
    b.spin += j * b.radius * b.inv_inertia;
    j
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(velocity: DVec2, spin: f64, radius: f64, mass: f64) -> RoughSide {
        RoughSide {
            velocity,
            spin,
            radius,
            inv_mass: 1.0 / mass,
            inv_inertia: 2.0 / (mass * radius * radius),
        }
    }

    /// Energy, momentum and angular momentum about the origin of two touching discs, the
    /// first at `pa`, the second at `pa + n (r_a + r_b)`.
    fn totals(pa: DVec2, n: DVec2, a: &RoughSide, b: &RoughSide) -> (f64, DVec2, f64) {
        let pb = pa + n * (a.radius + b.radius);
        let mut out = (0.0, DVec2::ZERO, 0.0);
        for (p, s) in [(pa, a), (pb, b)] {
            let (m, i) = (1.0 / s.inv_mass, 1.0 / s.inv_inertia);
            out.0 += 0.5 * m * s.velocity.length_squared() + 0.5 * i * s.spin * s.spin;
            out.1 += m * s.velocity;
            out.2 += m * p.perp_dot(s.velocity) + i * s.spin;
        }
        out
    }

    #[test]
    fn a_perfectly_rough_hit_keeps_energy_momentum_and_angular_momentum() {
        let n = DVec2::new(0.6, 0.8);
        let pa = DVec2::new(-3.0, 7.0);
        let mut a = disc(DVec2::new(1.5, -0.3), 2.0, 0.7, 2.0);
        let mut b = disc(DVec2::new(-0.4, 0.9), -5.0, 0.3, 0.5);
        let before = totals(pa, n, &a, &b);
        let slip = |a: &RoughSide, b: &RoughSide| {
            (a.velocity - b.velocity).dot(n.perp()) + a.spin * a.radius + b.spin * b.radius
        };
        let g = slip(&a, &b);
        let j = apply_rough_impulse(n, &mut a, &mut b, 1.0);
        assert!(j != 0.0);
        assert!((slip(&a, &b) + g).abs() < 1e-14, "the slip is reversed");
        let after = totals(pa, n, &a, &b);
        assert!((after.0 - before.0).abs() < 1e-13 * before.0);
        assert!((after.1 - before.1).length() < 1e-14);
        assert!((after.2 - before.2).abs() < 1e-13);
    }

    #[test]
    fn partly_rough_hits_lose_energy_and_smooth_ones_do_nothing() {
        let n = DVec2::X;
        for (beta, lost) in [(-1.0, false), (0.0, true), (0.5, true)] {
            let mut a = disc(DVec2::new(0.0, 1.0), 0.0, 1.0, 1.0);
            let mut b = disc(DVec2::ZERO, 0.0, 1.0, 1.0);
            let before = totals(DVec2::ZERO, n, &a, &b).0;
            let j = apply_rough_impulse(n, &mut a, &mut b, beta);
            let after = totals(DVec2::ZERO, n, &a, &b).0;
            assert_eq!(j != 0.0, lost, "β = {beta}");
            assert_eq!(after < before, lost, "β = {beta}");
        }
    }

    #[test]
    fn a_wall_or_an_immovable_circle_neither_moves_nor_turns() {
        let mut ball = disc(DVec2::new(2.0, -1.0), 3.0, 0.5, 1.0);
        let mut wall = RoughSide::fixed(DVec2::new(0.0, 0.0));
        apply_rough_impulse(-DVec2::Y, &mut ball, &mut wall, 0.5);
        assert_eq!(wall, RoughSide::fixed(DVec2::ZERO));
        // Two immovable sides: no impulse, nothing NaN.
        let mut other = RoughSide::fixed(DVec2::X);
        assert_eq!(
            apply_rough_impulse(DVec2::Y, &mut wall, &mut other, 1.0),
            0.0
        );
    }

    #[test]
    fn a_spinning_ball_dropped_on_a_rough_floor_leaves_it_moving_sideways() {
        // Spinning clockwise (ω < 0) and dropped on a floor below it: its bottom slips to the
        // left, so the floor pushes it to the right.
        let mut ball = disc(DVec2::new(0.0, -1.0), -4.0, 0.5, 1.0);
        let mut floor = RoughSide::fixed(DVec2::ZERO);
        apply_rough_impulse(-DVec2::Y, &mut ball, &mut floor, 0.0);
        assert!(ball.velocity.x > 0.0 && ball.spin > -4.0);
        // β = 0: it leaves rolling (no slip): v_x = −ω r.
        assert!((ball.velocity.x + ball.spin * ball.radius).abs() < 1e-15);
    }
}
