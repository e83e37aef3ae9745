//! Property tests of the numerical kernels with random inputs over many orders of magnitude:
//! time of impact, the contact kernel (impulse + separation), wall reflection, the event
//! engine and the rough hit. Each property is an invariant the code must keep for every input.

use crate::common::unit_box_gas;
use bevy::math::DVec2;
use moving_circles::base::arena::Arena;
use moving_circles::base::circle::{CircleState, disc_inverse_inertia};
use moving_circles::kernels::EventEngine;
use moving_circles::kernels::pair_time_of_impact;
use moving_circles::kernels::resolve_contact;
use moving_circles::kernels::{RoughSide, apply_rough_impulse};
use moving_circles::step::boundary::reflect_off_walls;
use proptest::prelude::*;

/// A number with a random sign and a magnitude from 1e-6 to 1e6.
fn wide() -> impl Strategy<Value = f64> {
    (-6.0f64..6.0, any::<bool>())
        .prop_map(|(e, neg)| if neg { -(10f64.powf(e)) } else { 10f64.powf(e) })
}

fn vector() -> impl Strategy<Value = DVec2> {
    (wide(), wide()).prop_map(|(x, y)| DVec2::new(x, y))
}

fn positive() -> impl Strategy<Value = f64> {
    (-4.0f64..4.0).prop_map(|e| 10f64.powf(e))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn time_of_impact_lands_on_contact_and_is_symmetric(dp in vector(), dv in vector(), sigma in positive()) {
        let t = pair_time_of_impact(dp, dv, sigma);
        // Swapping the pair flips both differences and must give the same answer.
        prop_assert_eq!(t, pair_time_of_impact(-dp, -dv, sigma));
        // Positions are known to the rounding of the larger of the offset and the contact
        // distance: the contact's resolution, 1e-12 of it (the bound was 1e-6, which let a
        // contact be 10⁴ σ off; at 1e-12 it found the discriminant taken as a difference of
        // two nearly equal squares, which lost 15 of 16 digits for a pair far apart).
        let scale = dp.length() + sigma;
        match t {
            Some(t) => {
                prop_assert!(t.is_finite() && t >= 0.0);
                if t > 0.0 {
                    let gap = (dp + dv * t).length();
                    prop_assert!((gap - sigma).abs() <= 1e-12 * scale, "gap {} vs sigma {}, dp {}, dv {}, t {}", gap, sigma, dp, dv, t);
                }
            }
            // A miss: apart and never closer than σ while approaching (the closest approach),
            // or already parting.
            None => {
                let closing = dp.dot(dv);
                if closing < 0.0 && dv != DVec2::ZERO {
                    let nearest = (dp - dv * (closing / dv.length_squared())).length();
                    prop_assert!(nearest >= sigma - 1e-12 * scale, "missed: passes {} apart, sigma {}", nearest, sigma);
                }
            }
        }
    }

    #[test]
    fn contacts_conserve_momentum_and_energy_and_leave_no_approach_or_overlap(
        pa in vector(), off in vector(), va in vector(), vb in vector(),
        ra in positive(), rb in positive(), ma in positive(), mb in positive(),
    ) {
        let mut a = CircleState::new(pa, va, ra).with_mass(ma);
        // Put b within reach of a, so the pair overlaps (the interesting case).
        let reach = (ra + rb) * 0.999;
        let mut b = CircleState::new(pa + off.normalize_or(DVec2::X) * (reach * 0.5), vb, rb).with_mass(mb);
        let (a0, b0) = (a, b);
        let p0 = va * ma + vb * mb;
        let e0 = 0.5 * ma * va.length_squared() + 0.5 * mb * vb.length_squared();
        resolve_contact(&mut a, &mut b, 1.0);
        for x in [a.position, a.velocity, b.position, b.velocity] {
            prop_assert!(x.is_finite());
        }
        let p1 = a.velocity * ma + b.velocity * mb;
        let e1 = 0.5 * ma * a.velocity.length_squared() + 0.5 * mb * b.velocity.length_squared();
        let p_scale = ma * va.length() + mb * vb.length();
        prop_assert!((p1 - p0).length() <= 1e-9 * p_scale, "momentum {} → {}", p0, p1);
        prop_assert!((e1 - e0).abs() <= 1e-9 * e0, "energy {} → {}", e0, e1);
        let d = b.position - a.position;
        prop_assert!(d.length() >= (ra + rb) * (1.0 - 1e-9) - 1e-9 * pa.length(), "still overlapping");
        let n = d.normalize_or(DVec2::X);
        prop_assert!((b.velocity - a.velocity).dot(n) >= -1e-9 * (va.length() + vb.length()), "still approaching");

        // Swapping the pair gives the mirrored result.
        let (mut a2, mut b2) = (b0, a0);
        resolve_contact(&mut a2, &mut b2, 1.0);
        prop_assert!((a2.velocity - b.velocity).length() <= 1e-9 * p_scale / ma.min(mb));
        prop_assert!((b2.velocity - a.velocity).length() <= 1e-9 * p_scale / ma.min(mb));
    }

    #[test]
    fn walls_keep_every_circle_inside_with_its_speed(p in vector(), v in vector(), r in 0.001f64..0.4) {
        let arena = Arena::centered(DVec2::splat(2.0));
        let (mut q, mut w) = (p, v);
        reflect_off_walls(&mut q, &mut w, r, &arena, 1.0);
        prop_assert!(q.is_finite() && w.is_finite());
        prop_assert!(q.cmpge(arena.min + r).all() && q.cmple(arena.max - r).all(), "{} ended at {}", p, q);
        prop_assert_eq!(w.abs(), v.abs());
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn the_event_engine_conserves_energy_and_never_overlaps(
        seeds in prop::collection::vec((0.05f64..0.95, 0.05f64..0.95, -1.0f64..1.0, -1.0f64..1.0, 0.005f64..0.03, 0.1f64..10.0), 2..40),
        periodic in any::<bool>(),
    ) {
        let (circles, arena) = unit_box_gas(&seeds, periodic);
        let energy = |e: &EventEngine| (0..e.len()).map(|i| 0.5 * circles[i].mass * e.velocity(i).length_squared()).sum::<f64>();
        let mut engine = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
        let e0 = energy(&engine);
        for step in 1..=20 {
            prop_assert!(engine.advance_to(step as f64 * 0.05, u64::MAX).is_ok());
            for i in 0..engine.len() {
                for j in i + 1..engine.len() {
                    let mut d = engine.position(j) - engine.position(i);
                    if periodic {
                        d -= d.round();
                    }
                    prop_assert!(d.length() >= (circles[i].radius + circles[j].radius) * (1.0 - 1e-9), "overlap after step {}", step);
                }
            }
        }
        prop_assert!((energy(&engine) - e0).abs() <= 1e-12 * e0.max(1e-300));
    }
}

/// One side of a rough hit: a disc of random velocity, spin, radius and mass (its inverse
/// inertia that of a uniform disc), or, one time in eight, something fixed (a wall, a static
/// circle).
fn rough_side() -> impl Strategy<Value = RoughSide> {
    (vector(), wide(), positive(), positive(), any::<u8>()).prop_map(|(v, w, r, m, kind)| {
        if kind % 8 == 0 {
            return RoughSide {
                radius: r,
                ..RoughSide::fixed(DVec2::ZERO)
            };
        }
        RoughSide {
            velocity: v,
            spin: w,
            radius: r,
            inv_mass: 1.0 / m,
            inv_inertia: disc_inverse_inertia(1.0 / m, r),
        }
    })
}

/// Energy (moving and turning), momentum and angular momentum about the origin of the movable
/// sides of a hit, `a` at `pa` and `b` touching it along `n`.
fn rough_totals(pa: DVec2, n: DVec2, a: &RoughSide, b: &RoughSide) -> (f64, DVec2, f64) {
    let pb = pa + n * (a.radius + b.radius);
    let mut out = (0.0, DVec2::ZERO, 0.0);
    for (p, s) in [(pa, a), (pb, b)] {
        if s.inv_mass == 0.0 {
            continue;
        }
        let (m, i) = (1.0 / s.inv_mass, 1.0 / s.inv_inertia);
        out.0 += 0.5 * m * s.velocity.length_squared() + 0.5 * i * s.spin * s.spin;
        out.1 += m * s.velocity;
        out.2 += m * p.perp_dot(s.velocity) + i * s.spin;
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn a_rough_hit_never_makes_energy_and_keeps_momentum_between_movable_discs(
        a in rough_side(),
        b in rough_side(),
        angle in 0.0f64..std::f64::consts::TAU,
        beta in -1.0f64..=1.0,
    ) {
        let n = DVec2::from_angle(angle);
        let (mut a2, mut b2) = (a, b);
        let before = rough_totals(DVec2::ZERO, n, &a, &b);
        let j = apply_rough_impulse(n, &mut a2, &mut b2, beta);
        let after = rough_totals(DVec2::ZERO, n, &a2, &b2);
        prop_assert!(j.is_finite());
        prop_assert!(a2.velocity.is_finite() && b2.velocity.is_finite());
        prop_assert!(a2.spin.is_finite() && b2.spin.is_finite());
        // Never more energy than before (up to rounding of the largest term).
        let scale = before.0.max(after.0);
        prop_assert!(after.0 <= before.0 + 1e-9 * scale, "{} -> {}", before.0, after.0);
        // Between two movable discs, momentum and angular momentum are kept (relative to the
        // sums of their magnitudes before and after: the impulse acts at the contact point).
        if a.inv_mass > 0.0 && b.inv_mass > 0.0 {
            let sides = [&a, &b, &a2, &b2];
            let m: f64 = sides.iter().map(|s| s.velocity.length() / s.inv_mass).sum();
            let lever = a.radius + b.radius;
            let l = m * lever + sides.iter().map(|s| s.spin.abs() / s.inv_inertia).sum::<f64>();
            prop_assert!((after.1 - before.1).length() <= 1e-9 * m.max(f64::MIN_POSITIVE));
            prop_assert!((after.2 - before.2).abs() <= 1e-9 * l.max(f64::MIN_POSITIVE));
        }
        // A fixed side neither moves nor turns.
        for (s, s2) in [(&a, &a2), (&b, &b2)] {
            if s.inv_mass == 0.0 {
                prop_assert_eq!(s.velocity, s2.velocity);
                prop_assert_eq!(s.spin, s2.spin);
            }
        }
    }
}
