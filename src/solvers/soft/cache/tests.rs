//! The contact cache's tests: warm starting finds each contact's own impulse, and a
//! checkpoint's cache is refused when it could not be one.

use bevy::math::DVec2;

use super::*;

/// A contact of circle `a` with circle `b` (by index, identity `b`) or, for `b` past the
/// circles, with segment wall `b`.
fn contact(a: u32, b: u32, impulse: f64) -> Constraint {
    let partner = match b {
        0..8 => Partner::Circle(u64::from(b)),
        _ => Partner::Wall(Wall::Segment(b)),
    };
    Constraint {
        a,
        b: if b < 8 { b } else { NONE },
        partner,
        normal: DVec2::X,
        anchor: DVec2::ZERO,
        reach: 1.0,
        inv_mass: (1.0, 1.0),
        normal_mass: 0.5,
        soft: super::super::Softness::new(30.0, 10.0, 1.0 / 240.0),
        restitution: 0.0,
        threshold: 0.0,
        push: 1.0,
        relative_velocity: 0.0,
        impulse,
        total_impulse: impulse,
        approach: 0.0,
        was_touching: false,
        pressing: false,
        turn: NONE,
    }
}

#[test]
fn each_contact_warm_starts_from_its_own_impulse_whatever_came_went_or_moved() {
    let ids: Vec<u64> = (0..8).collect();
    // Last step: every pair (a, b), a < b, of 8 circles and a wall each, in a fixed
    // order; its impulse names it.
    let named = |a: u32, b: u32| f64::from(a * 100 + b);
    let mut last: Vec<Constraint> = (0..8)
        .flat_map(|a| (a + 1..8).chain([20 + a]).map(move |b| (a, b)))
        .map(|(a, b)| contact(a, b, named(a, b)))
        .collect();
    let mut cache = ContactCache::default();
    cache.store(&ids, last.iter(), &[]);
    // This step: some gone, some new, a block moved far, neighbours swapped; in two
    // calls, as a step warm starts its walls and then its pairs.
    let other = |c: &Constraint| match c.partner {
        Partner::Circle(b) => b as u32,
        Partner::Wall(Wall::Segment(w)) => w,
        Partner::Wall(Wall::Arena(_)) => unreachable!("no arena walls here"),
    };
    last.retain(|c| (c.a + other(c)) % 5 != 0);
    last.rotate_left(7);
    last.swap(3, 4);
    last.extend([contact(0, 30, 0.0), contact(5, 31, 0.0)]);
    let mut now: Vec<Constraint> = last.iter().map(|c| contact(c.a, other(c), -1.0)).collect();
    let (first, second) = now.split_at_mut(10);
    cache.warm_start(&ids, first, &mut []);
    cache.warm_start(&ids, second, &mut []);
    for c in &now {
        let expected = match c.partner {
            Partner::Circle(b) => named(c.a, b as u32),
            Partner::Wall(Wall::Segment(w)) if w < 30 => named(c.a, w),
            Partner::Wall(_) => -1.0,
        };
        assert_eq!(c.impulse, expected, "contact {} {:?}", c.a, c.partner);
    }
    // With the circles in another order the same contacts are found by identity.
    let reversed: Vec<u64> = ids.iter().rev().copied().collect();
    let mut renamed: Vec<Constraint> = now
        .iter()
        .map(|c| contact(7 - c.a, other(c), -1.0))
        .collect();
    let (first, second) = renamed.split_at_mut(5);
    cache.warm_start(&reversed, first, &mut []);
    cache.warm_start(&reversed, second, &mut []);
    for (c, was) in renamed.iter().zip(&now) {
        assert_eq!(c.impulse, was.impulse, "contact {} {:?}", c.a, c.partner);
    }
    // Where the contact looked for first has the same partner but another circle.
    let two = [contact(0, 5, 1.0), contact(1, 5, 2.0)];
    cache.store(&ids, two.iter(), &[]);
    let mut one = [contact(1, 5, -1.0)];
    cache.warm_start(&ids, &mut one, &mut []);
    assert_eq!(one[0].impulse, 2.0);
}

#[test]
fn a_cached_impulse_beyond_any_speed_is_refused() {
    // Circle 0 has one contact, with circle 1: a light pair (the fuzz target's forged
    // impulse of 2.6e307 sent them to infinity on the warm start).
    let light = |x| CircleState::new(DVec2::new(x, 0.0), DVec2::ZERO, 0.1).with_mass(0.03);
    let circles = [light(0.0), light(0.2)];
    let contact = |partner, impulse, tangent, rolling| CachedContact {
        partner,
        impulse,
        touching: true,
        tangent,
        rolling,
    };
    let cache = |impulse, tangent, rolling| CacheSnapshot {
        counts: vec![1, 0],
        entries: vec![contact(
            SnapshotPartner::Circle(1),
            impulse,
            tangent,
            rolling,
        )],
    };
    assert!(cache(0.5, -0.2, 0.01).check(&circles).is_ok());
    assert!(cache(1e28, -1e28, 1e26).check(&circles).is_ok());
    for forged in [2.6e307, 1e30, -1.0, f64::NAN] {
        assert!(cache(forged, 0.0, 0.0).check(&circles).is_err(), "{forged}");
    }
    for forged in [-2.6e307, 1e30, f64::NAN, f64::INFINITY] {
        assert!(cache(0.5, forged, 0.0).check(&circles).is_err(), "{forged}");
        assert!(cache(0.5, 0.0, forged).check(&circles).is_err(), "{forged}");
    }
    // Against a wall only the circle's own mass counts; an immovable circle takes none.
    let wall = CacheSnapshot {
        counts: vec![1, 0],
        entries: vec![contact(
            SnapshotPartner::Wall(Wall::Segment(0)),
            1e30,
            0.0,
            0.0,
        )],
    };
    assert!(wall.check(&circles).is_err());
    let pegs = [circles[0].with_mass(f64::INFINITY), circles[1]];
    assert!(wall.check(&pegs).is_ok());
}
