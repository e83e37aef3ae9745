//! The exact tests behind the spatial queries, as plain functions: where a ray (or a moving
//! circle, which is a ray against shapes grown by its radius) first meets a disc or a segment
//! wall, and the contact it makes there.
//!
//! Shapes are solid: a ray that starts inside a disc, or a moving circle that starts
//! overlapping a shape, meets it at distance 0.

use bevy::math::DVec2;

use crate::base::segment::Segment;
use crate::collision::toi::{pair_time_of_impact, segment_time_of_impact};

/// Distance `t ≥ 0` along the unit `direction` from `origin` at which the ray first meets the
/// solid disc of `radius` about `centre`, or `None` if it never does. 0 if `origin` is inside
/// or on the rim.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::game::query::shapes::ray_disc;
///
/// assert_eq!(ray_disc(DVec2::ZERO, DVec2::X, DVec2::new(3.0, 0.0), 1.0), Some(2.0));
/// assert_eq!(ray_disc(DVec2::ZERO, -DVec2::X, DVec2::new(3.0, 0.0), 1.0), None);
/// assert_eq!(ray_disc(DVec2::ZERO, DVec2::X, DVec2::new(0.5, 0.0), 1.0), Some(0.0));
/// ```
#[inline]
pub fn ray_disc(origin: DVec2, direction: DVec2, centre: DVec2, radius: f64) -> Option<f64> {
    // Solid: from inside, met at once, whichever way the ray points; else the circles' time of
    // impact (NaN-safe: no meeting with a disc that is not there).
    if (origin - centre).length_squared() <= radius * radius {
        return Some(0.0);
    }
    pair_time_of_impact(origin - centre, direction, radius)
}

/// Distance `t ≥ 0` along the unit `direction` from `origin` at which the ray first comes
/// within `radius` of `segment` (meets the capsule of that radius around it; with radius 0,
/// crosses or touches the segment itself), or `None`. 0 if `origin` is already that near.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::game::query::shapes::ray_capsule;
/// use moving_circles::base::segment::Segment;
///
/// let floor = Segment::new(DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0));
/// assert_eq!(ray_capsule(DVec2::new(0.0, 3.0), -DVec2::Y, &floor, 0.0), Some(3.0));
/// assert_eq!(ray_capsule(DVec2::new(0.0, 3.0), -DVec2::Y, &floor, 0.5), Some(2.5));
/// assert_eq!(ray_capsule(DVec2::new(2.0, 3.0), -DVec2::Y, &floor, 0.5), None);
/// ```
pub fn ray_capsule(origin: DVec2, direction: DVec2, segment: &Segment, radius: f64) -> Option<f64> {
    // Solid, as `ray_disc`; else the segment walls' time of impact at unit speed.
    if segment.distance(origin) <= radius {
        return Some(0.0);
    }
    segment_time_of_impact(origin, direction, radius, segment)
}

/// The contact a circle of `radius` centred at `at` makes with a disc of `disc_radius` about
/// `centre`: the point on the disc's rim nearest `at`, and the unit normal there out of the
/// disc (towards `at`; against `direction` when the centres coincide).
pub fn disc_contact(
    at: DVec2,
    direction: DVec2,
    centre: DVec2,
    disc_radius: f64,
) -> (DVec2, DVec2) {
    let normal = (at - centre).try_normalize().unwrap_or(-direction);
    (centre + normal * disc_radius, normal)
}

/// The contact a circle centred at `at` makes with `segment`: the segment's point nearest
/// `at`, and the unit normal there out of the segment towards `at` (the face against
/// `direction` when `at` lies on the segment).
pub fn segment_contact(at: DVec2, direction: DVec2, segment: &Segment) -> (DVec2, DVec2) {
    let point = segment.closest_point(at);
    let normal = (at - point).try_normalize().unwrap_or_else(|| {
        let n = segment.normal();
        if n == DVec2::ZERO {
            -direction
        } else if n.dot(direction) > 0.0 {
            -n
        } else {
            n
        }
    });
    (point, normal)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_grazing_a_disc_meets_it_at_the_tangent_point() {
        let t = ray_disc(DVec2::new(-5.0, 1.0), DVec2::X, DVec2::ZERO, 1.0).unwrap();
        assert!((t - 5.0).abs() < 1e-6, "{t}");
        assert_eq!(
            ray_disc(DVec2::new(-5.0, 1.0 + 1e-9), DVec2::X, DVec2::ZERO, 1.0),
            None
        );
    }

    #[test]
    fn a_ray_meets_a_capsule_at_its_round_end_or_its_flat_face() {
        let s = Segment::new(DVec2::ZERO, DVec2::new(2.0, 0.0));
        // Along the segment's line, from the left: the round end at x = -0.5.
        let t = ray_capsule(DVec2::new(-3.0, 0.0), DVec2::X, &s, 0.5).unwrap();
        assert!((t - 2.5).abs() < 1e-12, "{t}");
        // Down onto the face, slanted.
        let d = DVec2::new(1.0, -1.0).normalize();
        let t = ray_capsule(DVec2::new(0.0, 2.0), d, &s, 0.5).unwrap();
        assert!((t - 1.5 * 2f64.sqrt()).abs() < 1e-12, "{t}");
        // A thin segment is crossed where the ray cuts it; parallel and beside it, never.
        let t = ray_capsule(DVec2::new(1.0, -1.0), DVec2::Y, &s, 0.0).unwrap();
        assert!((t - 1.0).abs() < 1e-12, "{t}");
        assert_eq!(ray_capsule(DVec2::new(-1.0, 0.1), DVec2::X, &s, 0.0), None);
    }

    #[test]
    fn contacts_face_the_circle() {
        let s = Segment::new(DVec2::ZERO, DVec2::new(2.0, 0.0));
        assert_eq!(
            segment_contact(DVec2::new(1.0, 0.5), -DVec2::Y, &s),
            (DVec2::new(1.0, 0.0), DVec2::Y)
        );
        assert_eq!(
            segment_contact(DVec2::new(1.0, 0.0), DVec2::Y, &s).1,
            -DVec2::Y
        );
        assert_eq!(
            disc_contact(DVec2::new(3.0, 0.0), DVec2::X, DVec2::ZERO, 1.0),
            (DVec2::X, DVec2::X)
        );
    }
}
