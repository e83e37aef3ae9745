//! Times of impact under gravity, as plain functions: a circle that falls flies a parabola,
//! `p + v·τ + ½a·τ²`. Two falling circles keep a constant relative velocity, so their pairs
//! use the straight-line [`pair_time_of_impact`](super::toi::pair_time_of_impact); what does
//! not fall (walls, segment walls, immovable and sleeping circles) needs the parabola's roots:
//! a quadratic against a line ([`exit_time`], [`falling_segment_time`]'s faces), a quartic
//! against a point or a circle ([`falling_pair_time`]), both solved in `roots.rs`.

use bevy::math::DVec2;

use super::roots::{first_entering_root, quadratic_roots};
use crate::base::segment::Segment;

/// When a point at `x` moving at `v` with acceleration `acc` along one axis first leaves
/// `[lo, hi]`: `(time, high)`, `high` for leaving through `hi`. A point already past a bound
/// and moving (or pushed) out through it leaves now. Used for the arena's walls (the centre's
/// bounds) and for cell crossings (the cell's edges).
///
/// ```
/// use moving_circles::kernels::exit_time;
///
/// // Dropped at rest from 0.5 under -4: it lands on 0 at τ = 0.5.
/// let (t, high) = exit_time(0.5, 0.0, -4.0, 0.0, 1.0).unwrap();
/// assert!((t - 0.5).abs() < 1e-15 && !high);
/// ```
pub fn exit_time(x: f64, v: f64, acc: f64, lo: f64, hi: f64) -> Option<(f64, bool)> {
    let out_low = v < 0.0 || (v == 0.0 && acc < 0.0);
    let out_high = v > 0.0 || (v == 0.0 && acc > 0.0);
    if x <= lo && out_low {
        return Some((0.0, false));
    }
    if x >= hi && out_high {
        return Some((0.0, true));
    }
    // Past a bound by rounding and moving back in too slowly to beat the acceleration: it
    // leaves where it turns, before it ever gets back inside.
    let turn = -v / acc;
    let turned = x + 0.5 * v * turn;
    if x < lo && acc < 0.0 && turned <= lo {
        return Some((turn, false));
    }
    if x > hi && acc > 0.0 && turned >= hi {
        return Some((turn, true));
    }
    // The first crossing of each bound in the outward direction.
    let first = |bound: f64, outward: f64| {
        quadratic_roots(0.5 * acc, v, x - bound)
            .into_iter()
            .flatten()
            .filter(|&t| t >= 0.0 && t.is_finite())
            .find(|&t| {
                let speed = v + acc * t;
                speed * outward > 0.0 || (speed == 0.0 && acc * outward > 0.0)
            })
    };
    match (first(lo, -1.0), first(hi, 1.0)) {
        (Some(l), Some(h)) => Some(if h < l { (h, true) } else { (l, false) }),
        (Some(l), None) => Some((l, false)),
        (None, Some(h)) => Some((h, true)),
        (None, None) => None,
    }
}

/// When two circles whose centres are `dp` apart (second minus first), closing at relative
/// velocity `dv` with relative acceleration `da` (one falls, the other does not), first come
/// within `sigma` of each other while approaching: the first `τ ≥ 0` where
/// `|dp + dv·τ + ½da·τ²| = σ` and the distance shrinks. Touching or overlapping by rounding
/// and approaching (or pushed together) now: `Some(0)`. A caller that only wants a time sooner
/// than `horizon` (one it already has) may get `None` for a later one: a pair too far apart to
/// meet by then is ruled out before any root is looked for.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::kernels::falling_pair_time;
///
/// // A ball 2 above a peg, radii summing to 1, dropped at rest under g = 2: it falls 1 in 1.
/// let (dp, dv, da) = (DVec2::new(0.0, -2.0), DVec2::ZERO, DVec2::new(0.0, 2.0));
/// let t = falling_pair_time(dp, dv, da, 1.0, f64::INFINITY);
/// assert!((t.unwrap() - 1.0).abs() < 1e-12);
/// // Not sooner than 0.5: ruled out.
/// assert_eq!(falling_pair_time(dp, dv, da, 1.0, 0.5), None);
/// ```
pub fn falling_pair_time(dp: DVec2, dv: DVec2, da: DVec2, sigma: f64, horizon: f64) -> Option<f64> {
    let a = 0.5 * da;
    // f(τ) = |a τ² + dv τ + dp|² − σ², highest power last.
    let c = [
        dp.length_squared() - sigma * sigma,
        2.0 * dv.dot(dp),
        dv.length_squared() + 2.0 * a.dot(dp),
        2.0 * a.dot(dv),
        a.length_squared(),
    ];
    if !c.iter().all(|x| x.is_finite()) {
        return None;
    }
    if c[0] <= 0.0 && (c[1] < 0.0 || (c[1] == 0.0 && c[2] < 0.0)) {
        return Some(0.0);
    }
    // The gap closes no faster than the relative speed and acceleration allow (with a margin
    // far above the rounding of the distance and the reach, so that no time sooner than the
    // horizon is ever ruled out).
    let distance = dp.length();
    if horizon.is_finite() {
        let reach = dv.length() * horizon + a.length() * horizon * horizon;
        let margin = 1e-9 * (distance + sigma + reach);
        if distance - sigma - reach > margin {
            return None;
        }
        // Tighter, along the line between them now: the distance is at least its part along
        // `u`, `|dp| + (dv·u)·τ + (a·u)·τ²`, whose least value over `[0, horizon]` is at an
        // end or where it turns. A pair side by side under gravity is ruled out here.
        if distance > 0.0 {
            let u = dp / distance;
            let (w, alpha) = (dv.dot(u), a.dot(u));
            let along = |t: f64| distance + w * t + alpha * t * t;
            let turn = -w / (2.0 * alpha);
            let mut least = along(0.0).min(along(horizon));
            if turn > 0.0 && turn < horizon {
                least = least.min(along(turn));
            }
            if least - sigma > margin {
                return None;
            }
        }
    }
    // Apart for good: along some direction the gap never closes to `sigma`, whatever the
    // horizon. Along the axes (a pair side by side drifting apart, a peg above the top of the
    // arc) and along the line between them now.
    let apart = |u: DVec2| stays_beyond(u.dot(dp), u.dot(dv), u.dot(a), sigma);
    if [DVec2::X, DVec2::NEG_X, DVec2::Y, DVec2::NEG_Y]
        .into_iter()
        .any(apart)
        || (distance > 0.0 && apart(dp / distance))
    {
        return None;
    }
    first_entering_root(&c, horizon)
}

/// Whether `x + w·τ + α·τ²`, a pair's gap along one direction, stays above `sigma` for every
/// `τ ≥ 0`, by a margin far above the rounding of its least value: then the distance, which is
/// at least that, never comes down to `sigma` either. A rule-out only: `false` when unsure
/// (a gap that shrinks without end, values not numbers).
fn stays_beyond(x: f64, w: f64, alpha: f64, sigma: f64) -> bool {
    let (least, scale) = if w >= 0.0 && alpha >= 0.0 {
        (x, x.abs())
    } else if alpha > 0.0 {
        // Least where it turns, at τ = −w / 2α.
        let dip = w * w / (4.0 * alpha);
        (x - dip, x.abs() + dip)
    } else {
        return false;
    };
    least - sigma > 1e-9 * (scale + sigma)
}

/// When a circle of radius `r` at `p` moving at `v` with acceleration `acc` first touches
/// `segment`: the sooner of touching a face (the contact point between the ends) and touching
/// an end (a point). Touching or overlapping it by rounding and approaching: `Some(0)`.
pub fn falling_segment_time(
    p: DVec2,
    v: DVec2,
    acc: DVec2,
    r: f64,
    segment: &Segment,
) -> Option<f64> {
    let ends = [segment.a, segment.b]
        .into_iter()
        .filter_map(|end| falling_pair_time(end - p, -v, -acc, r, f64::INFINITY));
    let face = falling_face_time(p, v, acc, r, segment);
    face.into_iter().chain(ends).reduce(f64::min)
}

/// When the falling circle touches a face of `segment` at a point between its ends: the first
/// time its centre comes within `r` of the segment's line, approaching it, at a point over the
/// segment. A parabola may enter that band beyond an end (touching nothing), leave it on the
/// other side and come back down onto the face: every entry is looked at, not only the first.
fn falling_face_time(p: DVec2, v: DVec2, acc: DVec2, r: f64, segment: &Segment) -> Option<f64> {
    let d = segment.b - segment.a;
    let length = d.length();
    if length == 0.0 {
        return None;
    }
    let u = d / length;
    let n = u.perp();
    // Signed distance from the line, its rate and its acceleration.
    let (s, w, alpha) = ((p - segment.a).dot(n), v.dot(n), acc.dot(n));
    let over_face = |t: f64| {
        let at = p + v * t + 0.5 * acc * t * t;
        t.is_finite() && (0.0..=length).contains(&(at - segment.a).dot(u))
    };
    // Now, on the side it is on: touching or past the band's edge by rounding and moving in.
    let now = if s >= 0.0 {
        exit_time(s, w, alpha, r, f64::INFINITY).filter(|&(_, high)| !high)
    } else {
        exit_time(s, w, alpha, f64::NEG_INFINITY, -r).filter(|&(_, high)| high)
    }
    .map(|(t, _)| t);
    if let Some(t) = now.filter(|&t| over_face(t)) {
        return Some(t);
    }
    // Later entries into the band `|s| < r`: down through `+r` or up through `-r`.
    let rate = |t: f64| w + alpha * t;
    let from_above = quadratic_roots(0.5 * alpha, w, s - r)
        .into_iter()
        .flatten()
        .filter(|&t| rate(t) < 0.0);
    let from_below = quadratic_roots(0.5 * alpha, w, s + r)
        .into_iter()
        .flatten()
        .filter(|&t| rate(t) > 0.0);
    from_above
        .chain(from_below)
        .filter(|&t| t >= 0.0 && over_face(t))
        .reduce(f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ball_dropped_on_a_floor_lands_when_its_fall_equals_its_height() {
        // 1.25 above its lowest position, g = -10: lands at τ = 0.5, then bounced up at 5 it
        // would leave through the ceiling at 2 only if it rose that far.
        let (t, high) = exit_time(1.25, 0.0, -10.0, 0.0, 2.0).unwrap();
        assert!((t - 0.5).abs() < 1e-15 && !high);
        let (t, high) = exit_time(0.0, 5.0, -10.0, 0.0, 2.0).unwrap();
        assert!(
            (t - 1.0).abs() < 1e-15 && !high,
            "apex 1.25 < 2: back on the floor"
        );
        let (t, high) = exit_time(0.0, 7.0, -10.0, 0.0, 2.0).unwrap();
        assert!(high && (0.0 + 7.0 * t - 5.0 * t * t - 2.0).abs() < 1e-12);
        // At rest on the floor, pressed into it: leaves (hits) now.
        assert_eq!(exit_time(0.0, 0.0, -10.0, 0.0, 2.0), Some((0.0, false)));
        assert_eq!(exit_time(1.0, 0.0, 0.0, 0.0, 2.0), None);
    }

    #[test]
    fn a_falling_ball_meets_a_peg_on_its_parabola() {
        // Thrown sideways at 1 from (−1, 1) above a peg at the origin, g = (0, −2), radii 0.5:
        // it touches the peg where |path − peg| = 1.
        let (p, v, g) = (
            DVec2::new(-1.0, 1.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, -2.0),
        );
        let t = falling_pair_time(-p, -v, -g, 1.0, f64::INFINITY).unwrap();
        let at = p + v * t + 0.5 * g * t * t;
        assert!((at.length() - 1.0).abs() < 1e-12, "at {at}, t = {t}");
        // Before that it was clear of the peg all along.
        for k in 0..100 {
            let s = t * k as f64 / 100.0;
            let q = p + v * s + 0.5 * g * s * s;
            assert!(q.length() >= 1.0 - 1e-12, "inside at {s}");
        }
    }

    #[test]
    fn a_ball_that_rises_past_a_segments_end_and_falls_back_onto_its_face_hits_the_face() {
        // The slope scene at restitution 1: a ball bounced up off the floor right of the slope's
        // lower end, rose through the line beyond the end and fell back onto the face. Only the
        // first entry into the band within r of the line was looked at (beyond the end, so
        // none), the end point's hit came 0.034 too deep and the snap out of the face gained
        // 0.29 J.
        let segment = Segment {
            a: DVec2::new(-7.9, 3.5),
            b: DVec2::new(2.0, -2.3),
        };
        let (p, v, acc, r) = (
            DVec2::new(4.346774857870392, -4.2),
            DVec2::new(-1.9667547300671548, 7.67198765927831),
            DVec2::new(0.0, -9.81),
            0.3,
        );
        let t = falling_segment_time(p, v, acc, r, &segment).unwrap();
        let at = p + v * t + 0.5 * acc * t * t;
        let (_, _, distance) = segment.contact(at, v + acc * t);
        assert!((distance - r).abs() < 1e-12, "at {at}: {distance} from it");
        for k in 0..1000 {
            let s = t * k as f64 / 1000.0;
            let q = p + v * s + 0.5 * acc * s * s;
            assert!(segment.contact(q, v).2 >= r - 1e-12, "inside at {s}");
        }
    }

    #[test]
    fn a_vanishing_gravity_meets_a_peg_when_the_straight_line_does() {
        // The checkpoint campaign's `swept` find: a circle falling at 0.81 onto a peg 0.012
        // away under g = 1.8e-136. The quartic's top coefficients (g², g·v) are hundreds of
        // orders below the rest, its turning points 10¹³⁵ away: the root search once stopped
        // there, the hit was missed and the circle sank 0.2 % of its radius into the peg.
        let (p, v) = (
            DVec2::new(0.20374394109042002, 0.4495482472869555),
            DVec2::new(8.66478600110202e-309, -0.8125),
        );
        let sigma = 0.2 + 0.2817738302337065;
        let straight = falling_pair_time(-p, -v, DVec2::ZERO, sigma, f64::INFINITY).unwrap();
        for g in [1.786e-136, 1e-300, 1e-60, 1e-20] {
            for horizon in [0.016666667, f64::INFINITY] {
                let t = falling_pair_time(-p, -v, DVec2::new(0.0, -g), sigma, horizon);
                assert!(
                    t.is_some_and(|t| (t - straight).abs() <= 1e-12 * straight),
                    "g = {g:e}, horizon {horizon}: {t:?}, straight {straight}"
                );
            }
        }
    }

    #[test]
    fn a_parabola_that_passes_beside_a_peg_never_meets_it() {
        // Dropped 2 to the side of the peg: straight down, never within 1.
        let t = falling_pair_time(
            DVec2::new(2.0, -3.0),
            DVec2::ZERO,
            DVec2::new(0.0, 2.0),
            1.0,
            f64::INFINITY,
        );
        assert_eq!(t, None);
        // Thrown up past the peg's side and falling back beside it: the second pass is the
        // first within reach.
        let t = falling_pair_time(
            DVec2::new(1.5, 0.0),
            DVec2::new(0.0, 3.0),
            DVec2::new(0.0, -2.0),
            1.0,
            f64::INFINITY,
        );
        assert_eq!(t, None);
    }

    #[test]
    fn touching_by_rounding_and_leaving_too_slowly_to_part_is_a_hit_where_it_turns() {
        // Overlapping a peg below by rounding, moving up at 1e-9 under g = 2: it never parts
        // from the peg; it hits it when it turns, at τ = 5e-10, instead of sinking in unseen.
        let (dp, dv, da) = (
            DVec2::new(0.0, -(1.0 - 1e-15)),
            DVec2::new(0.0, -1e-9),
            DVec2::new(0.0, 2.0),
        );
        let t = falling_pair_time(dp, dv, da, 1.0, f64::INFINITY).expect("the hit is found");
        assert!((t - 5e-10).abs() < 1e-15, "{t}");
        // The same against a floor: a centre below its bound by rounding, moving up slowly.
        let (t, high) = exit_time(-1e-16, 1e-9, -2.0, 0.0, 1.0).unwrap();
        assert!(!high && (t - 5e-10).abs() < 1e-15, "{t}");
    }

    #[test]
    fn resting_on_a_peg_and_pressed_into_it_is_a_hit_now() {
        let t = falling_pair_time(
            DVec2::new(0.0, -1.0),
            DVec2::ZERO,
            DVec2::new(0.0, 2.0),
            1.0,
            f64::INFINITY,
        );
        assert_eq!(t, Some(0.0));
        // Overlapping by rounding but moving away fast enough to beat gravity for a while: the
        // next hit is after it comes back down.
        let t = falling_pair_time(
            DVec2::new(0.0, -1.0 + 1e-16),
            DVec2::new(0.0, -4.0),
            DVec2::new(0.0, 2.0),
            1.0,
            f64::INFINITY,
        )
        .unwrap();
        assert!((t - 4.0).abs() < 1e-9, "{t}");
    }

    #[test]
    fn a_ball_lands_on_a_sloped_face_and_on_an_end() {
        // A floor segment from (−1, 0) to (1, 0); a ball of radius 0.5 dropped from height 2.5
        // at x = 0 under g = 2 touches the face when it has fallen 2: at τ = √2.
        let floor = Segment::new(DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0));
        let g = DVec2::new(0.0, -2.0);
        let t = falling_segment_time(DVec2::new(0.0, 2.5), DVec2::ZERO, g, 0.5, &floor).unwrap();
        assert!((t - 2f64.sqrt()).abs() < 1e-12, "{t}");
        // Dropped at x = 1.3: past the end, it lands on the end where its centre is 0.5 away.
        let t = falling_segment_time(DVec2::new(1.3, 2.5), DVec2::ZERO, g, 0.5, &floor).unwrap();
        let at = DVec2::new(1.3, 2.5) + 0.5 * g * t * t;
        assert!(
            (at.distance(DVec2::new(1.0, 0.0)) - 0.5).abs() < 1e-12,
            "{at}"
        );
        // Dropped at x = 1.6: misses.
        let miss = falling_segment_time(DVec2::new(1.6, 2.5), DVec2::ZERO, g, 0.5, &floor);
        assert_eq!(miss, None);
    }

    /// The first contact found against the first sign change of dense sampling, on random
    /// throws at a peg (positions, velocities and gravity of either sign), with and without a
    /// horizon.
    #[test]
    fn the_first_contact_matches_dense_sampling() {
        use rand::{Rng, SeedableRng};
        use rand_chacha::ChaCha8Rng;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let (horizon, samples) = (4.0, 20_000);
        let mut checked = 0;
        for _ in 0..3000 {
            let dp = DVec2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
            if dp.length() < 1.0 {
                continue;
            }
            let dv = DVec2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
            let da = DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-10.0..10.0));
            let found = falling_pair_time(dp, dv, da, 1.0, f64::INFINITY);
            let gap = |t: f64| (dp + dv * t + 0.5 * da * t * t).length() - 1.0;
            let step = horizon / samples as f64;
            let sampled = (1..=samples)
                .map(|s| s as f64 * step)
                .find(|&t| gap(t) <= 0.0);
            match (found, sampled) {
                (Some(t), Some(s)) => assert!(t <= s && t > s - step - 1e-12, "{dp} {dv} {da}"),
                (Some(t), None) => assert!(t > horizon - step, "{dp} {dv} {da}: {t}"),
                (None, s) => assert_eq!(s, None, "{dp} {dv} {da}: missed"),
            }
            // A horizon rules out only later times, and changes no time it finds.
            for h in [0.1, 0.5, 2.0] {
                match (found, falling_pair_time(dp, dv, da, 1.0, h)) {
                    (Some(t), Some(u)) => assert_eq!(t, u, "{dp} {dv} {da}"),
                    (Some(t), None) => assert!(t >= h, "{dp} {dv} {da}: {t} ruled out by {h}"),
                    (None, u) => assert_eq!(u, None, "{dp} {dv} {da}"),
                }
            }
            checked += 1;
        }
        assert!(checked > 2000);
    }
}
