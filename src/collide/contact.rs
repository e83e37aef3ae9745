//! Narrow phase of the `discrete` solver for one pair: positional separation along the contact
//! normal split by inverse mass, then the restitution impulse if (and only if) the pair is still
//! approaching. Plain functions over plain data.

use bevy::math::DVec2;

/// One circle as the contact kernel sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    /// Centre.
    pub position: DVec2,
    /// Velocity.
    pub velocity: DVec2,
    /// Radius.
    pub radius: f64,
    /// `1 / mass`; zero for an immovable circle.
    pub inv_mass: f64,
}

/// What [`resolve_contact`] did to a pair.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ContactOutcome {
    /// Overlap depth before separation, as a fraction of the smaller radius (0 if apart).
    pub penetration: f64,
    /// Magnitude of the impulse applied (0 if the pair was not approaching). Non-zero means a
    /// collision to count; `(r_a + r_b) · impulse` summed over collisions gives the virial.
    pub impulse: f64,
}

/// The contact normal from `a` to `b`. Coincident centres have no direction of their own; they
/// get one from the relative velocity, or `+x` if that is zero too, so no NaN can arise.
pub fn contact_normal(a: &Body, b: &Body) -> (DVec2, f64) {
    let d = b.position - a.position;
    let dist = d.length();
    if dist > 0.0 && dist.is_finite() {
        return (d / dist, dist);
    }
    let closing = a.velocity - b.velocity;
    (closing.try_normalize().unwrap_or(DVec2::X), 0.0)
}

/// Resolves one pair in place if it overlaps: separates it and applies the impulse
/// `j = -(1 + e)(v_rel · n) / (1/m_a + 1/m_b)` when the pair approaches.
///
/// With `restitution = 1` the impulse conserves kinetic energy and momentum exactly (up to
/// rounding); separation moves positions only, so it changes neither.
pub fn resolve_contact(a: &mut Body, b: &mut Body, restitution: f64) -> ContactOutcome {
    let reach = a.radius + b.radius;
    if a.position.distance_squared(b.position) >= reach * reach {
        return ContactOutcome::default();
    }
    let total_inv_mass = a.inv_mass + b.inv_mass;
    let (n, dist) = contact_normal(a, b);
    let overlap = reach - dist;
    let outcome_penetration = overlap / a.radius.min(b.radius);
    if total_inv_mass <= 0.0 {
        // Two immovable circles: nothing can move.
        return ContactOutcome {
            penetration: outcome_penetration,
            impulse: 0.0,
        };
    }
    a.position -= n * (overlap * a.inv_mass / total_inv_mass);
    b.position += n * (overlap * b.inv_mass / total_inv_mass);

    let approach = (b.velocity - a.velocity).dot(n);
    let mut impulse = 0.0;
    if approach < 0.0 {
        impulse = -(1.0 + restitution) * approach / total_inv_mass;
        a.velocity -= n * (impulse * a.inv_mass);
        b.velocity += n * (impulse * b.inv_mass);
    }
    ContactOutcome {
        penetration: outcome_penetration,
        impulse,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(x: f64, y: f64, vx: f64, vy: f64) -> Body {
        Body {
            position: DVec2::new(x, y),
            velocity: DVec2::new(vx, vy),
            radius: 0.5,
            inv_mass: 1.0,
        }
    }

    #[test]
    fn equal_masses_head_on_swap_velocities() {
        let (mut a, mut b) = (body(0.0, 0.0, 1.0, 0.0), body(0.9, 0.0, -2.0, 0.0));
        let out = resolve_contact(&mut a, &mut b, 1.0);
        assert_eq!(out.impulse, 3.0, "j = (1 + e)·|v_rel| / (2/m) = 2·3/2");
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
        let mut wall = body(0.0, 0.0, 0.0, 0.0);
        wall.inv_mass = 0.0;
        let mut ball = body(0.8, 0.0, -3.0, 0.0);
        resolve_contact(&mut wall, &mut ball, 1.0);
        assert_eq!(wall.position, DVec2::ZERO);
        assert_eq!(wall.velocity, DVec2::ZERO);
        assert_eq!(ball.velocity, DVec2::new(3.0, 0.0));
        assert!((ball.position.x - 1.0).abs() < 1e-6);
    }
}
