//! Times of impact for straight-line motion: circle-circle and circle-wall. Plain functions,
//! written to stay exact for touching and rounding-overlapped pairs.

use bevy::math::DVec2;

/// When two circles moving in straight lines first touch, if they do: the smallest `τ ≥ 0` with
/// `|dp + dv·τ| = σ`, where `dp = p_b - p_a`, `dv = v_b - v_a` and `σ = r_a + r_b`.
///
/// A pair that is approaching (`dp·dv < 0`) and already overlaps by rounding (`|dp| < σ`)
/// collides now (`Some(0)`); a pair that is separating never does, whatever its overlap.
/// The root is taken in the form `c / (-b + √disc)`, which does not cancel when the pair is
/// far apart and fast.
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
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None; // closest approach misses
    }
    let t = c / (-b + disc.sqrt());
    t.is_finite().then_some(t.max(0.0))
}

/// When a circle at `x` moving at `v` along one axis reaches the wall that keeps its centre in
/// `[lo, hi]`, if it moves toward one: `(time, which)` with `which` 0 for `lo`, 1 for `hi`.
/// A centre already past the wall it moves toward hits it now.
pub fn wall_time_of_impact(x: f64, v: f64, lo: f64, hi: f64) -> Option<(f64, usize)> {
    if v > 0.0 {
        Some((((hi - x) / v).max(0.0), 1))
    } else if v < 0.0 {
        Some((((lo - x) / v).max(0.0), 0))
    } else {
        None
    }
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
        assert_eq!(wall_time_of_impact(0.5, 2.0, 0.1, 0.9), Some((0.2, 1)));
        let (t, w) = wall_time_of_impact(0.5, -0.5, 0.1, 0.9).unwrap();
        assert!((t - 0.8).abs() < 1e-15 && w == 0);
        assert_eq!(wall_time_of_impact(0.95, 1.0, 0.1, 0.9), Some((0.0, 1)));
        assert_eq!(wall_time_of_impact(0.5, 0.0, 0.1, 0.9), None);
    }
}
