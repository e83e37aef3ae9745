//! Times of impact for straight-line motion: circle-circle, circle-wall and circle-segment.
//! Plain functions, written to stay exact for touching and rounding-overlapped pairs.

use bevy::math::DVec2;

use crate::base::segment::Segment;

/// When two circles moving in straight lines first touch, if they do: the smallest `τ ≥ 0` with
/// `|dp + dv·τ| = σ`, where `dp = p_b - p_a`, `dv = v_b - v_a` and `σ = r_a + r_b`.
///
/// A pair that is approaching (`dp·dv < 0`) and already overlaps by rounding (`|dp| < σ`)
/// collides now (`Some(0)`); a pair that is separating never does, whatever its overlap.
/// The root is taken in the form `c / (-b + √disc)`, which does not cancel when the pair is
/// far apart and fast, and the discriminant `b² - a·c` as `|dv|²σ² - (dp × dv)²` (Lagrange's
/// identity), which does not cancel either: for a pair far apart the two squares of the first
/// form are nearly equal (a pair 23 378 apart closing at 157 680, σ = 0.0029, lost 15 of its 16
/// digits and met 2e-10 of the offset off contact).
pub fn pair_time_of_impact(dp: DVec2, dv: DVec2, sigma: f64) -> Option<f64> {
    let b = dp.dot(dv);
    if b >= 0.0 {
        return None; // separating or moving in parallel
    }
    let a = dv.length_squared();
    let c = dp.length_squared() - sigma * sigma;
    if c <= 0.0 {
        return Some(0.0); // touching or overlapped by rounding, and approaching
    }
    let cross = dp.perp_dot(dv);
    let disc = a * (sigma * sigma) - cross * cross;
    if disc < 0.0 {
        return None; // closest approach misses
    }
    let t = c / (-b + disc.sqrt());
    t.is_finite().then_some(t.max(0.0))
}

/// [`pair_time_of_impact`] for circles whose radii grow (a compression): the smallest `τ ≥ 0`
/// with `|dp + dv·τ| = σ + γ·τ`, where `γ` is how fast the sum of the radii grows.
///
/// Growth catches up with any pair that does not fly apart faster than it: a pair separating
/// slower than `γ` meets again. Touching or overlapping by rounding, a pair collides now if its
/// gap closes (`dp·dv < σγ`) and otherwise next when growth has closed it again. With `γ = 0`
/// this is [`pair_time_of_impact`].
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::growing_pair_time_of_impact;
///
/// // At rest, 3 apart, radii summing to 1 and growing at 0.5: they touch at τ = 4.
/// let t = growing_pair_time_of_impact(DVec2::new(3.0, 0.0), DVec2::ZERO, 1.0, 0.5);
/// assert_eq!(t, Some(4.0));
/// ```
pub fn growing_pair_time_of_impact(dp: DVec2, dv: DVec2, sigma: f64, gamma: f64) -> Option<f64> {
    if gamma == 0.0 {
        return pair_time_of_impact(dp, dv, sigma);
    }
    // |dp + dv·τ|² - (σ + γτ)² = aτ² + 2bτ + c.
    let b = dp.dot(dv) - sigma * gamma;
    let a = dv.length_squared() - gamma * gamma;
    let c = dp.length_squared() - sigma * sigma;
    let t = if b < 0.0 {
        if c <= 0.0 {
            return Some(0.0); // touching and closing
        }
        let disc = b * b - a * c;
        if disc < 0.0 {
            return None; // closest approach misses (only when they outrun the growth)
        }
        c / (-b + disc.sqrt())
    } else {
        if a >= 0.0 {
            return None; // flying apart faster than they grow, for good
        }
        // Growth outruns them: the later root, with `-a > 0` and `b ≥ 0`.
        let disc = b * b - a * c;
        if disc < 0.0 {
            return None;
        }
        (b + disc.sqrt()) / -a
    };
    t.is_finite().then_some(t.max(0.0))
}

/// When a circle at `x` moving at `v` along one axis reaches the wall that keeps its centre in
/// `[lo, hi]`, if it moves toward one: `(time, which)` with `which` 0 for `lo`, 1 for `hi`.
/// A centre already past the wall it moves toward hits it now. `growth` is how fast the
/// circle's radius grows (0 but in a compression): both bounds then close in at that speed, so
/// a circle meets a wall it moves away from slower than it grows, and one at rest meets both.
pub fn wall_time_of_impact(x: f64, v: f64, lo: f64, hi: f64, growth: f64) -> Option<(f64, usize)> {
    let to_hi = (v + growth > 0.0).then(|| (((hi - x) / (v + growth)).max(0.0), 1));
    let to_lo = (v - growth < 0.0).then(|| (((lo - x) / (v - growth)).max(0.0), 0));
    match (to_lo, to_hi) {
        (Some(l), Some(h)) => Some(if h.0 < l.0 { h } else { l }),
        (l, h) => l.or(h),
    }
}

/// When a circle of radius `r` at `p` moving at `v` first touches `segment`, if it does: the
/// soonest of touching a face (the contact point strictly between the ends) and touching an end
/// (a point, like a circle of radius 0). A circle already touching or overlapping it by
/// rounding and moving towards it touches it now (`Some(0)`); one moving away never does.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::segment_time_of_impact;
/// use moving_circles::base::segment::Segment;
///
/// let wall = Segment::new(DVec2::new(0.0, -1.0), DVec2::new(0.0, 1.0));
/// // 2 to the left, radius 0.5, speed 3 to the right: the gap of 1.5 closes at t = 0.5.
/// let t = segment_time_of_impact(DVec2::new(-2.0, 0.0), DVec2::new(3.0, 0.0), 0.5, &wall);
/// assert_eq!(t, Some(0.5));
/// // Passing 0.4 above the upper end: the rounded end is hit, 0.3 before the centre is level
/// // with it.
/// let t = segment_time_of_impact(DVec2::new(-2.0, 1.4), DVec2::new(3.0, 0.0), 0.5, &wall);
/// assert!((t.unwrap() - 1.7 / 3.0).abs() < 1e-12);
/// ```
pub fn segment_time_of_impact(p: DVec2, v: DVec2, r: f64, segment: &Segment) -> Option<f64> {
    let ends = [segment.a, segment.b]
        .into_iter()
        .filter_map(|end| pair_time_of_impact(p - end, v, r));
    let face = face_time_of_impact(p, v, r, segment);
    face.into_iter().chain(ends).reduce(f64::min)
}

/// When the circle touches one face of `segment` at a point strictly between its ends.
fn face_time_of_impact(p: DVec2, v: DVec2, r: f64, segment: &Segment) -> Option<f64> {
    let d = segment.b - segment.a;
    let length = d.length();
    if length == 0.0 {
        return None;
    }
    let u = d / length;
    let n = u.perp();
    let s = (p - segment.a).dot(n); // signed distance from the line
    let w = v.dot(n); // speed along the normal
    // Approaching the line from the side the centre is on (from exactly on it: any way).
    let gap = if s > 0.0 && w < 0.0 {
        (s - r) / -w
    } else if s < 0.0 && w > 0.0 {
        (-s - r) / w
    } else if s == 0.0 && w != 0.0 {
        0.0
    } else {
        return None;
    };
    let t = gap.max(0.0);
    let along = (p + v * t - segment.a).dot(u);
    (t.is_finite() && (0.0..=length).contains(&along)).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_pairs_meet_when_the_gap_closes() {
        let t = pair_time_of_impact(DVec2::new(3.0, 0.0), DVec2::new(-2.0, 0.0), 1.0).unwrap();
        assert!((t - 1.0).abs() < 1e-15);
    }

    #[test]
    fn misses_and_separating_pairs_never_meet() {
        assert_eq!(
            pair_time_of_impact(DVec2::new(3.0, 2.0), DVec2::new(-1.0, 0.0), 1.0),
            None
        );
        assert_eq!(
            pair_time_of_impact(DVec2::new(3.0, 0.0), DVec2::new(1.0, 0.0), 1.0),
            None
        );
        // Overlapping but separating: left alone.
        assert_eq!(
            pair_time_of_impact(DVec2::new(0.9, 0.0), DVec2::new(1.0, 0.0), 1.0),
            None
        );
    }

    #[test]
    fn rounding_overlap_while_approaching_collides_now() {
        assert_eq!(
            pair_time_of_impact(DVec2::new(1.0 - 1e-15, 0.0), DVec2::new(-1.0, 0.0), 1.0),
            Some(0.0)
        );
    }

    #[test]
    fn grazing_paths_touch_once() {
        // Tangent: closest approach exactly σ.
        let t = pair_time_of_impact(DVec2::new(5.0, 1.0), DVec2::new(-1.0, 0.0), 1.0).unwrap();
        assert!((t - 5.0).abs() < 1e-7, "{t}");
    }

    #[test]
    fn walls_are_hit_in_the_direction_of_motion() {
        assert_eq!(wall_time_of_impact(0.5, 2.0, 0.1, 0.9, 0.0), Some((0.2, 1)));
        let (t, w) = wall_time_of_impact(0.5, -0.5, 0.1, 0.9, 0.0).unwrap();
        assert!((t - 0.8).abs() < 1e-15 && w == 0);
        assert_eq!(
            wall_time_of_impact(0.95, 1.0, 0.1, 0.9, 0.0),
            Some((0.0, 1))
        );
        assert_eq!(wall_time_of_impact(0.5, 0.0, 0.1, 0.9, 0.0), None);
    }

    #[test]
    fn growing_circles_meet_walls_they_move_away_from() {
        let close = |got: Option<(f64, usize)>, t: f64, wall: usize| {
            let (at, which) = got.unwrap();
            assert!((at - t).abs() < 1e-15 && which == wall, "{got:?}");
        };
        // At rest, growing at 0.1: the nearer wall (0.2 away) first.
        close(wall_time_of_impact(0.3, 0.0, 0.1, 0.9, 0.1), 2.0, 0);
        // Moving to the high wall at 0.1, growing at 0.1: closes at 0.2 there, 0 to the low one.
        close(wall_time_of_impact(0.5, 0.1, 0.1, 0.9, 0.1), 2.0, 1);
        // Moving away from the low wall faster than it grows: only the high wall.
        close(wall_time_of_impact(0.2, 0.5, 0.1, 0.9, 0.1), 0.7 / 0.6, 1);
    }

    #[test]
    fn growth_catches_up_with_slow_separation() {
        // 2 apart and separating at 0.5, radii summing to 1 and growing at 1:
        // 2 + 0.5τ = 1 + τ at τ = 2.
        let t = growing_pair_time_of_impact(DVec2::new(2.0, 0.0), DVec2::new(0.5, 0.0), 1.0, 1.0);
        assert_eq!(t, Some(2.0));
        // Separating faster than they grow: never.
        let never =
            growing_pair_time_of_impact(DVec2::new(2.0, 0.0), DVec2::new(2.0, 0.0), 1.0, 1.0);
        assert_eq!(never, None);
        // Touching, separating slower than growth: closing in the frame of the surfaces, now.
        let now = growing_pair_time_of_impact(DVec2::new(1.0, 0.0), DVec2::new(0.5, 0.0), 1.0, 1.0);
        assert_eq!(now, Some(0.0));
        // Without growth it is the plain time of impact.
        for (dp, dv) in [
            (DVec2::new(3.0, 0.4), DVec2::new(-2.0, 0.1)),
            (DVec2::new(5.0, 1.0), DVec2::new(-1.0, 0.0)),
            (DVec2::new(3.0, 2.0), DVec2::new(-1.0, 0.0)),
        ] {
            assert_eq!(
                growing_pair_time_of_impact(dp, dv, 1.0, 0.0),
                pair_time_of_impact(dp, dv, 1.0)
            );
        }
    }

    fn horizontal() -> Segment {
        Segment::new(DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0))
    }

    #[test]
    fn faces_are_hit_from_either_side_and_ends_head_on() {
        let s = horizontal();
        let down = segment_time_of_impact(DVec2::new(0.3, 2.0), DVec2::new(0.0, -1.0), 0.5, &s);
        assert_eq!(down, Some(1.5));
        let up = segment_time_of_impact(DVec2::new(0.3, -2.0), DVec2::new(0.0, 2.0), 0.5, &s);
        assert_eq!(up, Some(0.75));
        // Along the line into the right end: the end is a point, met at distance r.
        let end = segment_time_of_impact(DVec2::new(3.0, 0.0), DVec2::new(-1.0, 0.0), 0.5, &s);
        assert!((end.unwrap() - 1.5).abs() < 1e-15, "{end:?}");
    }

    #[test]
    fn sliding_along_a_face_or_moving_away_never_hits() {
        let s = horizontal();
        // Touching the face, moving parallel to it: no face hit, only the tangent touch of
        // the far end when it gets there (which turns no velocity).
        let along = segment_time_of_impact(DVec2::new(-0.5, 0.5), DVec2::new(1.0, 0.0), 0.5, &s);
        assert_eq!(along, Some(1.5));
        // Touching it, moving away.
        let away = segment_time_of_impact(DVec2::new(0.0, 0.5), DVec2::new(0.3, 1.0), 0.5, &s);
        assert_eq!(away, None);
        // Overlapping by rounding, approaching: now.
        let now =
            segment_time_of_impact(DVec2::new(0.0, 0.5 - 1e-16), DVec2::new(0.0, -1.0), 0.5, &s);
        assert_eq!(now, Some(0.0));
    }

    #[test]
    fn passing_beside_an_end_misses_or_grazes_it() {
        let s = horizontal();
        // Moving down, 0.6 to the right of the right end: misses (radius 0.5).
        let miss = segment_time_of_impact(DVec2::new(1.6, 2.0), DVec2::new(0.0, -1.0), 0.5, &s);
        assert_eq!(miss, None);
        // 0.4 to the right: touches the end where the distance is 0.5, at height 0.3.
        let graze = segment_time_of_impact(DVec2::new(1.4, 2.0), DVec2::new(0.0, -1.0), 0.5, &s);
        assert!((graze.unwrap() - 1.7).abs() < 1e-12, "{graze:?}");
    }

    #[test]
    fn a_fast_circle_far_away_hits_a_thin_segment() {
        // 10 diameters per unit time, 30 diameters away: the face, not a miss.
        let s = Segment::new(DVec2::new(0.0, -1.0), DVec2::new(0.0, 1.0));
        let t = segment_time_of_impact(DVec2::new(-3.0, 0.2), DVec2::new(1.0, 0.0), 0.05, &s);
        assert!((t.unwrap() - 2.95).abs() < 1e-12, "{t:?}");
    }
}
