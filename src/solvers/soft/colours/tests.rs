//! The colours' packing (every pair once, in the colour greedy colouring gives it; last step's
//! groups reused cleanly) and the vector passes against the lane-by-lane ones, bit for bit.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::*;
use crate::base::grid::NONE;
use crate::solvers::soft::bodies::Softness;
use crate::solvers::soft::contacts::Partner;

/// `n` contacts among `circles` circles (some immovable), some touching, some open, with
/// impulses, velocities and positions at random.
fn scene(seed: u64, circles: usize, n: usize) -> (Vec<Constraint>, Vec<DVec2>, Vec<DVec2>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut any = |lo: f64, hi: f64| rng.random_range(lo..hi);
    let position = (0..circles).map(|_| DVec2::new(any(-5.0, 5.0), any(-5.0, 5.0)));
    let position: Vec<DVec2> = position.collect();
    let velocity = (0..circles).map(|_| DVec2::new(any(-2.0, 2.0), any(-2.0, 2.0)));
    let velocity: Vec<DVec2> = velocity.collect();
    let inv_mass: Vec<f64> = (0..circles)
        .map(|i| if i % 7 == 3 { 0.0 } else { any(0.2, 3.0) })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
    let pairs = (0..n)
        .filter_map(|_| {
            let (a, b) = (rng.random_range(0..circles), rng.random_range(0..circles));
            let (wa, wb) = (inv_mass[a], inv_mass[b]);
            if a == b || wa + wb == 0.0 {
                return None;
            }
            let normal = (position[b] - position[a]).normalize_or(DVec2::X);
            let soft = Softness::new(30.0, 10.0, 1.0 / 240.0);
            Some(Constraint {
                a: a as u32,
                b: b as u32,
                partner: Partner::Circle(b as u64),
                normal,
                anchor: DVec2::new(rng.random_range(-0.1..0.1), 0.0),
                // Half overlapping, half open.
                reach: position[a].distance(position[b]) + rng.random_range(-0.05..0.05),
                inv_mass: (wa, wb),
                normal_mass: 1.0 / (wa + wb),
                soft,
                restitution: 0.3,
                threshold: 0.01,
                push: rng.random_range(0.5..3.0),
                relative_velocity: -0.5,
                impulse: rng.random_range(-0.1f64..0.4).max(0.0),
                total_impulse: 0.0,
                approach: 0.0,
                was_touching: false,
                pressing: false,
                turn: NONE,
            })
        })
        .collect();
    (pairs, position, velocity)
}

/// Each colour's pairs, by index, as its groups' live lanes hold them (checking that only a
/// colour's last group has empty lanes).
fn packed(colours: &mut Colours) -> Vec<Vec<u32>> {
    colours
        .groups_mut()
        .map(|groups| {
            let last = groups.len().saturating_sub(1);
            for g in &groups[..last] {
                assert!(
                    g.live.iter().all(|&live| live),
                    "a full group before the last"
                );
            }
            let lanes = groups.iter().flat_map(|g| (0..LANES).map(move |l| (g, l)));
            let live = lanes.filter(|(g, l)| g.live[*l]);
            live.map(|(g, l)| g.contact[l]).collect()
        })
        .collect()
}

#[test]
fn every_pair_is_packed_once_in_the_first_colour_its_circles_leave_free() {
    for (circles, n) in [(50, 40), (200, 900), (30, 2000), (3, 500)] {
        let (pairs, ..) = scene(circles as u64, circles, n);
        let mut colours = Colours::default();
        colours.pack(circles, &pairs);
        // The greedy colouring worked out plainly: each pair takes the first colour that no
        // earlier pair on one of its movable circles took.
        let mut taken = vec![std::collections::BTreeSet::new(); circles];
        let mut expected = vec![Vec::new(); MAX_COLOURS as usize];
        let mut rest = Vec::new();
        for (k, c) in pairs.iter().enumerate() {
            let sides = [(c.a, c.inv_mass.0), (c.b, c.inv_mass.1)];
            let movable = sides
                .iter()
                .filter(|(_, w)| *w > 0.0)
                .map(|&(i, _)| i as usize);
            let free = (0..MAX_COLOURS).find(|x| movable.clone().all(|i| !taken[i].contains(x)));
            match free {
                Some(colour) => {
                    movable.for_each(|i| {
                        taken[i].insert(colour);
                    });
                    expected[colour as usize].push(k as u32);
                }
                None => rest.push(k as u32),
            }
        }
        assert_eq!(
            packed(&mut colours),
            expected,
            "{circles} circles, {n} pairs"
        );
        assert_eq!(colours.rest, rest);
        if circles == 3 {
            assert!(!rest.is_empty(), "hundreds of contacts on three circles");
        }
    }
    // A circle with more contacts than colours: the rest go one by one.
    let template = scene(5, 200, 50).0[0];
    let star: Vec<Constraint> = (1..100u32)
        .map(|b| Constraint {
            a: 0,
            b,
            inv_mass: (1.0, 1.0),
            ..template
        })
        .collect();
    let mut colours = Colours::default();
    colours.pack(100, &star);
    assert_eq!(colours.rest.len(), 99 - MAX_COLOURS as usize);
}

#[test]
fn groups_packed_over_last_steps_hold_only_this_steps_pairs() {
    let mut colours = Colours::default();
    let (many, ..) = scene(3, 300, 2000);
    colours.pack(300, &many);
    let (few, ..) = scene(4, 40, 30);
    colours.pack(40, &few);
    let mut fresh = Colours::default();
    fresh.pack(40, &few);
    let lanes = |c: &Colours| -> Vec<(u32, u32, u32)> {
        c.groups()
            .flat_map(|g| (0..LANES).map(move |l| (g, l)))
            .map(|(g, l)| match g.live[l] {
                true => (g.contact[l], g.a[l], g.b[l]),
                false => (u32::MAX, g.a[l], g.b[l]),
            })
            .collect()
    };
    assert_eq!(lanes(&colours), lanes(&fresh));
}

/// Runs every kind of pass three times over `scene`'s groups with `run`, and returns the
/// velocities, the groups and the work, as bits.
fn passes_with(
    run: impl Fn(&mut Colours, &[DVec2], &mut [DVec2], Pass, &mut Work),
    seed: u64,
) -> Vec<u64> {
    let (pairs, position, mut velocity) = scene(seed, 300, 1500);
    let mut colours = Colours::default();
    colours.pack(position.len(), &pairs);
    let mut work = Work::default();
    for _ in 0..3 {
        for pass in [
            Pass::WarmStart,
            Pass::Solve {
                inv_h: 240.0,
                bias: true,
            },
            Pass::Solve {
                inv_h: 240.0,
                bias: false,
            },
        ] {
            run(&mut colours, &position, &mut velocity, pass, &mut work);
        }
    }
    let mut solved = pairs.clone();
    colours.unpack(&mut solved);
    let velocities = velocity.iter().flat_map(|v| [v.x, v.y]);
    let impulses = solved
        .iter()
        .flat_map(|c| [c.impulse, c.total_impulse, c.approach]);
    let work = [work.energy, work.momentum.x, work.momentum.y];
    velocities
        .chain(impulses)
        .chain(work)
        .map(f64::to_bits)
        .collect()
}

#[test]
fn the_vector_passes_give_the_lane_by_lane_passes_bit_for_bit() {
    for seed in 0..4 {
        let by_lane = passes_with(passes_by_lane, seed);
        assert_eq!(by_lane, passes_with(passes, seed), "seed {seed}");
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            let wide = |g: &mut Colours, p: &[DVec2], v: &mut [DVec2], pass, w: &mut Work| {
                // SAFETY: the processor has AVX2.
                unsafe { wide::passes(g, p, v, pass, w) }
            };
            assert_eq!(by_lane, passes_with(wide, seed), "seed {seed}: AVX2");
        } else {
            eprintln!("no AVX2 here: only the lane-by-lane passes were compared");
        }
    }
}
