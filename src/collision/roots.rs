//! Real roots of the small polynomials times of impact lead to, as plain functions:
//! [`quadratic_roots`] in the forms that do not cancel, and [`first_entering_root`], the first
//! time a quartic (a distance squared against a reach squared) falls to zero, found by
//! splitting the line at its turning points and refining by safeguarded Newton steps. Nothing
//! here allocates: they run for every pair of a falling and a resting circle.

/// The real roots of `a·τ² + b·τ + c`, smaller first (`None` for a missing one), taken in the
/// forms that do not cancel.
pub fn quadratic_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a == 0.0 {
        return if b == 0.0 {
            [None, None]
        } else {
            [Some(-c / b), None]
        };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || !disc.is_finite() {
        return [None, None];
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let (r1, r2) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    let (lo, hi) = if r1 <= r2 { (r1, r2) } else { (r2, r1) };
    [Some(lo), Some(hi)]
}

/// The first `τ ≥ 0` at which the polynomial `c` (coefficients from the constant up, degree at
/// most 4, positive leading coefficient) goes from positive to zero, or starts to fall while at
/// or below zero: the turning points (roots of its derivative) split `[0, ∞)` into pieces where
/// it is monotonic, and the first piece that falls from above zero to zero or below holds the
/// root, or the first that falls from zero or below starts at it. Pieces that begin at or after
/// `horizon` are not looked at (`None`, as if there were no root), so a caller that only wants a
/// root sooner than one it has stops early; a root that is found does not depend on `horizon`.
pub fn first_entering_root(c: &[f64; 5], horizon: f64) -> Option<f64> {
    let f = |t: f64| horner(c, t);
    let derivative = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4]];
    let (turns, count) = cubic_roots_after_zero(&derivative);
    let mut from = 0.0;
    for &to in turns[..count].iter().chain(&[f64::INFINITY]) {
        if from >= horizon {
            return None;
        }
        let end = if to.is_finite() { to } else { far_end(c, from) };
        let (f_from, f_to) = (f(from), f(end));
        if f_from > 0.0 && f_to <= 0.0 {
            return Some(refine(c, (from, f_from), (end, f_to)));
        }
        // Touching (or overlapping by rounding) where it turns to approach: a hit there, before
        // it would sink in.
        if f_from <= 0.0 && f_to < f_from {
            return Some(from);
        }
        from = end;
        if !to.is_finite() {
            break;
        }
    }
    None
}

/// A point past which the polynomial `c` (positive leading coefficient) only grows, at or
/// after `from`: Cauchy's bound on its derivative's roots.
fn far_end(c: &[f64; 5], from: f64) -> f64 {
    let top = c[4];
    if top <= 0.0 {
        return from;
    }
    let bound = 1.0
        + [c[1], 2.0 * c[2], 3.0 * c[3]]
            .iter()
            .map(|x| (x / (4.0 * top)).abs())
            .fold(0.0, f64::max);
    bound.max(from)
}

fn horner(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &k| acc * t + k)
}

/// The real roots `τ > 0` of the cubic `d` (constant first), in increasing order, and how many
/// there are: its own turning points (a quadratic's roots) split the line into monotonic
/// pieces, each solved by safeguarded Newton steps from the closed form's estimate.
fn cubic_roots_after_zero(d: &[f64; 4]) -> ([f64; 3], usize) {
    let g = |t: f64| horner(d, t);
    let mut cuts = [0.0; 3];
    let mut n = 0;
    for t in quadratic_roots(3.0 * d[3], 2.0 * d[2], d[1])
        .into_iter()
        .flatten()
    {
        if t > 0.0 && t.is_finite() {
            cuts[n] = t;
            n += 1;
        }
    }
    let mut roots = [0.0; 3];
    let bound = if d[3] != 0.0 {
        1.0 + [d[0], d[1], d[2]]
            .iter()
            .map(|x| (x / d[3]).abs())
            .fold(0.0, f64::max)
    } else if d[2] != 0.0 {
        1.0 + [d[0], d[1]]
            .iter()
            .map(|x| (x / d[2]).abs())
            .fold(0.0, f64::max)
    } else if d[1] != 0.0 {
        1.0 + (d[0] / d[1]).abs()
    } else {
        return (roots, 0);
    };
    cuts[n] = bound;
    let estimates = cubic_estimates(d);
    let mut count = 0;
    let mut from = 0.0;
    for &to in &cuts[..=n] {
        // A piece holds at most one root, and there are at most three pieces.
        if to <= from || count == 3 {
            continue;
        }
        let (a, b) = (g(from), g(to));
        if a == 0.0 && from > 0.0 {
            roots[count] = from;
            count += 1;
        } else if (a < 0.0) != (b < 0.0) && b != 0.0 {
            // Newton from the closed form's root in the piece, where there is one: a few
            // steps to the last bit instead of tens from the middle.
            let guess = estimates
                .iter()
                .copied()
                .find(|&t| t > from && t < to)
                .unwrap_or(0.5 * (from + to));
            roots[count] = monotonic_root(d, from, to, guess);
            count += 1;
        }
        from = to;
    }
    (roots, count)
}

/// The real roots of the cubic `d` (constant first) by the closed form (Cardano's, or the
/// trigonometric one for three roots), as starting points only: rounding may put them off by
/// far more than the last bit, and a missing one is `NaN`.
fn cubic_estimates(d: &[f64; 4]) -> [f64; 3] {
    if d[3] == 0.0 {
        let [lo, hi] = quadratic_roots(d[2], d[1], d[0]);
        return [lo.unwrap_or(f64::NAN), hi.unwrap_or(f64::NAN), f64::NAN];
    }
    let (a, b, c) = (d[2] / d[3], d[1] / d[3], d[0] / d[3]);
    // t = x − a/3: x³ + p·x + q = 0.
    let p = b - a * a / 3.0;
    let q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
    let shift = -a / 3.0;
    let disc = 0.25 * q * q + p * p * p / 27.0;
    if disc > 0.0 {
        let s = disc.sqrt();
        [
            shift + (-0.5 * q + s).cbrt() + (-0.5 * q - s).cbrt(),
            f64::NAN,
            f64::NAN,
        ]
    } else if p < 0.0 {
        let r = 2.0 * (-p / 3.0).sqrt();
        let phi = ((3.0 * q / (2.0 * p)) * (-3.0 / p).sqrt())
            .clamp(-1.0, 1.0)
            .acos()
            / 3.0;
        let third = std::f64::consts::TAU / 3.0;
        [0.0, 1.0, 2.0].map(|k| shift + r * (phi - third * k).cos())
    } else {
        [shift, f64::NAN, f64::NAN]
    }
}

/// A root of the cubic `d` in `[a, b]`, where it is monotonic and its values at the ends differ
/// in sign, from `guess` inside: Newton steps kept inside a shrinking bracket (bisection
/// whenever a step would leave it), to the last bit.
fn monotonic_root(d: &[f64; 4], a: f64, b: f64, guess: f64) -> f64 {
    let slope = [d[1], 2.0 * d[2], 3.0 * d[3]];
    let below = horner(d, a) < 0.0;
    let value = |t: f64| (horner(d, t), horner(&slope, t));
    bracketed_newton(value, |g| (g < 0.0) == below, (a, b), guess).0
}

/// Newton steps a root search takes before it only bisects (see [`bracketed_newton`]): from a
/// good start a root is found in under ten.
const NEWTON_STEPS: u32 = 40;

/// Newton steps on `value` (its value and slope at a point) from `start`, kept inside the
/// bracket `(a, b)` as it shrinks (bisection whenever a step would leave it), until a step
/// lands on an end: a point moves the end `a` when `on_a_side` says its value is on `a`'s side
/// of zero, else the end `b`. Newton converging from one side stops moving; the number next to
/// it then decides, so the bracket ends two numbers wide in a few steps more. Returns the final
/// bracket.
///
/// A start far from the root on a polynomial whose coefficients span hundreds of orders of
/// magnitude (a vanishing gravity) makes Newton crawl, halving a bracket 10¹³⁵ wide per step.
/// After [`NEWTON_STEPS`] the search bisects the numbers themselves ([`split`]), which ends
/// two numbers wide in at most 64 more steps whatever the scale.
fn bracketed_newton(
    value: impl Fn(f64) -> (f64, f64),
    on_a_side: impl Fn(f64) -> bool,
    (mut a, mut b): (f64, f64),
    start: f64,
) -> (f64, f64) {
    let mut t = start;
    // Each split halves the numbers left (at most 2⁶⁴, one more for a bracket across zero).
    for step in 1..=NEWTON_STEPS + 66 {
        let (ft, slope) = value(t);
        if on_a_side(ft) {
            a = t;
        } else {
            b = t;
        }
        let newton = t - ft / slope;
        t = if step >= NEWTON_STEPS {
            split(a, b)
        } else if newton > a && newton < b && newton.is_finite() {
            newton
        } else if newton == t {
            // Converged from one side: the next number towards the other end settles which
            // side the root is on, instead of halving a bracket whose far end never moved.
            if t == a { a.next_up() } else { b.next_down() }
        } else {
            0.5 * (a + b)
        };
        if t <= a || t >= b {
            break;
        }
    }
    (a, b)
}

/// The middle number of `[a, b]` as the numbers are laid out, not as they are spaced: halfway
/// between their bit patterns (zero splits a bracket across it), so that each split halves
/// how many numbers are left. An end when no number lies between them.
fn split(a: f64, b: f64) -> f64 {
    if a < 0.0 && b > 0.0 {
        0.0
    } else if b <= 0.0 {
        -split(-b, -a)
    } else {
        // From +0 (never −0, whose pattern is the sign bit); `b` finite or infinite: the sum
        // of two patterns below 0x7FF1… fits.
        let low = if a > 0.0 { a.to_bits() } else { 0 };
        f64::from_bits((low + b.to_bits()) / 2)
    }
}

/// The first `τ` in `[a, b]` where the polynomial `c`, `fa > 0` at `a` and `fb ≤ 0` at `b` and
/// monotonic between, reaches zero: Newton steps from where the chord between the ends
/// crosses zero, kept inside a shrinking bracket (bisection whenever a step would leave it),
/// to the last bit. Returns the bracket's upper end, where
/// the polynomial is zero or below: the contact is then reached, never missed by rounding.
fn refine(c: &[f64; 5], (a, fa): (f64, f64), (b, fb): (f64, f64)) -> f64 {
    let d = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4]];
    let value = |t: f64| (horner(c, t), horner(&d, t));
    let secant = a + fa * (b - a) / (fa - fb);
    let start = if secant > a && secant < b { secant } else { a };
    bracketed_newton(value, |f| f > 0.0, (a, b), start).1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_exact_for_far_apart_roots() {
        // τ² − 1e8 τ + 1 = 0: roots 1e-8 and 1e8; the naive formula loses the small one.
        let [lo, hi] = quadratic_roots(1.0, -1e8, 1.0);
        assert!((lo.unwrap() - 1e-8).abs() < 1e-22);
        assert!((hi.unwrap() - 1e8).abs() < 1e-6);
        assert_eq!(quadratic_roots(1.0, 0.0, 1.0), [None, None]);
        assert_eq!(quadratic_roots(0.0, 2.0, -4.0), [Some(2.0), None]);
    }

    #[test]
    fn newton_converging_from_one_side_ends_in_a_few_steps_on_two_neighbouring_numbers() {
        // Cubics bracketed far wider than their root, from near it on either side: Newton
        // converges without ever moving the far end, and halving the bracket after that took
        // 23 to 56 steps.
        for (d, guess) in [
            ([-1.0, 0.0, 0.0, 1.0], 1.0 + 1e-6),
            ([-1.0, 0.0, 0.0, 1.0], 1.0 - 1e-6),
            ([-2.0, 0.0, 1.0, 0.0], 1.5),
            ([-8.0, 1.0, -3.0, 1.0], 3.0),
        ] {
            let calls = std::cell::Cell::new(0);
            let slope = [d[1], 2.0 * d[2], 3.0 * d[3]];
            let value = |t: f64| {
                calls.set(calls.get() + 1);
                (horner(&d, t), horner(&slope, t))
            };
            let (a, b) = bracketed_newton(value, |g| g < 0.0, (0.0, 1e6), guess);
            assert_eq!(a.next_up(), b, "{d:?}: [{a}, {b}]");
            assert!(horner(&d, a) < 0.0 && horner(&d, b) >= 0.0, "{d:?}");
            assert!(
                calls.get() <= 8,
                "{d:?} from {guess}: {} steps",
                calls.get()
            );
        }
    }

    #[test]
    fn a_root_far_from_the_start_is_found_in_a_bounded_number_of_steps() {
        // τ² − 1 bracketed by (0, 10³⁰⁰) from 10³⁰⁰: Newton halves τ per step and would need
        // a thousand; bisecting the numbers ends on the root's two numbers in about a hundred.
        let d = [-1.0, 0.0, 1.0, 0.0];
        let calls = std::cell::Cell::new(0);
        let value = |t: f64| {
            calls.set(calls.get() + 1);
            (horner(&d, t), 2.0 * t)
        };
        let (a, b) = bracketed_newton(value, |g| g < 0.0, (0.0, 1e300), 1e300);
        assert_eq!((a.next_up(), b), (b, 1.0), "[{a}, {b}]");
        assert!(calls.get() <= NEWTON_STEPS + 66, "{} steps", calls.get());
        // Across zero and below it, split halves the numbers between the ends.
        assert_eq!(split(-1.0, 1.0), 0.0);
        assert_eq!(split(-4.0, -1.0), -2.0);
        assert_eq!(split(1.0, 1.0f64.next_up()), 1.0);
        assert_eq!(split(1.0, 4.0), 2.0);
        // A zero of either sign splits as +0.
        assert!((-1.0..0.0).contains(&split(-1.0, 0.0)));
        assert!((0.0..1.0).contains(&split(-0.0, 1.0)) && split(-0.0, 1.0) > 0.0);
    }

    #[test]
    fn a_cubics_roots_are_found_from_the_closed_forms_estimates() {
        // (τ − 1)(τ − 2)(τ − 3): three roots, estimated by the trigonometric form.
        let three = [-6.0, 11.0, -6.0, 1.0];
        let mut estimates = cubic_estimates(&three);
        estimates.sort_by(f64::total_cmp);
        for (e, root) in estimates.iter().zip([1.0, 2.0, 3.0]) {
            assert!((e - root).abs() < 1e-12, "{estimates:?}");
        }
        let (roots, count) = cubic_roots_after_zero(&three);
        assert_eq!(count, 3);
        for (r, root) in roots.iter().zip([1.0, 2.0, 3.0]) {
            assert!((r - root).abs() < 1e-14, "{roots:?}");
        }
        // τ³ − 8: one real root, by Cardano's form.
        let one = [-8.0, 0.0, 0.0, 1.0];
        assert!((cubic_estimates(&one)[0] - 2.0).abs() < 1e-12);
        assert_eq!(cubic_roots_after_zero(&one).1, 1);
        assert!((cubic_roots_after_zero(&one).0[0] - 2.0).abs() < 1e-15);
    }
}
