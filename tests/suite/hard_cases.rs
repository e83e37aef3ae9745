//! The hard-case suite: every file in `tests/hard/` under every solver, each checked against
//! the invariants that solver promises (docs/testing.md, "Hard cases"):
//!
//! | invariant | exact | swept | substeps=4 | discrete |
//! |---|---|---|---|---|
//! | no NaN or infinity | ✓ | ✓ | ✓ | ✓ |
//! | nothing leaves the arena | ✓ | ✓ | ✓ | ✓ |
//! | overlap after any step | ≤ 1e-9 r (rounding) | ≤ 1e-9 r | bounded, ≤ 1.5 r | bounded, ≤ 1.5 r |
//! | an overlap beyond rounding lasts at most | 0 steps | 0 steps | 60 steps | 60 steps |
//! | energy drift (e = 1) | ≤ 1e-9 | ≤ 1e-6 | ≤ 1e-6 | ≤ 1e-6 |
//! | momentum over each step in which no wall or immovable circle acted | ≤ 1e-9 | ≤ 1e-9 | ≤ 1e-9 | ≤ 1e-9 |
//! | case-specific promise | ✓ | ✓ | where promised | where promised |
//!
//! `soft` (at 4 and 8 substeps) has the bounds of `substeps=4` on overlap only where its contacts do not
//! press (0.08 r), and its energy bound is per case ([`soft_energy_bound`]): where many contacts
//! meet in one step it loses energy, measured and stated case by case.
//!
//! Run `cargo test --test suite hard_cases:: -- --nocapture` to see the measured values.
//!
//! The event solvers' hard cases under gravity are in `gravity.rs` beside their other gravity
//! tests: an elastic gas at every magnitude from 1e-12 to 1e6 in four directions, and over six
//! shapes of segment walls with their ends and corners hit, each within 1e-12 of its energy.

use std::collections::HashMap;
use std::path::Path;

use crate::common::*;
use bevy::math::DVec2;
use bevy::prelude::*;
use moving_circles::base::circle::{CircleState, discs, snapshot};
use moving_circles::kernels::overlapping_circles;
use moving_circles::prelude::*;
use moving_circles::tools::run::run_steps;
use moving_circles::tools::scene::particles;

/// Overlap (in smaller radii) that is rounding, not penetration.
const ROUNDING: f64 = 1e-9;

fn load(name: &str) -> CirclesConfig {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/hard")
        .join(name);
    if name.ends_with(".txt") {
        let circles = particles::read(&path, Boundary::Walls).unwrap_or_else(|e| panic!("{e}"));
        particles::to_config(circles, Boundary::Walls)
    } else {
        Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
    }
}

/// What a run of one case under one solver measured.
#[derive(Debug, Default)]
struct Outcome {
    non_finite: usize,
    escaped: usize,
    max_overlap: f64,
    longest_overlap_steps: u32,
    energy_drift: f64,
    /// The same, signed: positive is energy gained.
    energy_change: f64,
    /// The largest change of momentum over one step in which no wall or immovable circle
    /// acted, relative to `Σ m |v|` at the start (`None` if every step had one).
    momentum_drift: Option<f64>,
    pair_collisions: u64,
    wall_collisions: u64,
    start: Vec<CircleState>,
    end: Vec<CircleState>,
}

/// Runs `steps` steps of case `name` under `solver` through the same loop `moving_circles run`
/// uses, following every overlap beyond rounding from step to step.
fn run(name: &str, solver: Solver, steps: u64) -> Outcome {
    let config = CirclesConfig {
        solver,
        ..load(name)
    };
    let arena = config.arena;
    let mut app = create_app(config);
    let start = snapshot(app.world_mut());
    let mut longest_overlap_steps = 0;
    let mut overlapped_for: HashMap<(usize, usize), u32> = HashMap::new();
    let mut end = Vec::new();
    let scale: f64 = start.iter().map(|c| c.mass * c.velocity.length()).sum();
    // Momentum changes only where a wall or an immovable circle pushes: over every step in
    // which neither did, it is kept.
    let outside = |world: &World| {
        let pairs = world.resource::<PairCollisions>();
        (
            world.resource::<WallCollisions>().count,
            pairs.immovable_impulse,
        )
    };
    let mut last = (outside(app.world()), momentum_of(&start));
    let mut momentum_drift: Option<f64> = None;
    let report = run_steps(&mut app, name, steps, 1, |mut sample| {
        let pushed = outside(sample.world);
        let now = &sample.circles();
        let momentum = momentum_of(now);
        if pushed == last.0 && scale > 0.0 {
            let drift = (momentum - last.1).length() / scale;
            momentum_drift = Some(momentum_drift.unwrap_or(0.0).max(drift));
        }
        last = (pushed, momentum);
        let mut still = HashMap::new();
        for (i, j, depth) in overlapping_circles(&discs(now), &arena, &[]) {
            // Touching to rounding (exactly touching circles) is contact, not an overlap to fix.
            if depth / now[i].radius.min(now[j].radius) <= ROUNDING {
                continue;
            }
            let steps = overlapped_for.get(&(i, j)).copied().unwrap_or(0) + 1;
            longest_overlap_steps = longest_overlap_steps.max(steps);
            still.insert((i, j), steps);
        }
        overlapped_for = still;
        end = now.to_vec();
    });
    assert_eq!(
        report.steps, steps,
        "{name} under {solver}: fixed steps run"
    );
    Outcome {
        non_finite: report.non_finite,
        escaped: report.escaped,
        max_overlap: report.max_penetration,
        longest_overlap_steps,
        energy_drift: report.energy_drift.abs(),
        energy_change: report.energy_drift,
        momentum_drift,
        pair_collisions: report.pair_collisions,
        wall_collisions: report.wall_collisions,
        start,
        end,
    }
}

/// Runs `name` under every solver, checks the common invariants and returns the outcomes for
/// case-specific checks.
fn suite(name: &str, steps: u64) -> Vec<(Solver, Outcome)> {
    SOLVERS
        .into_iter()
        .map(|solver| {
            let o = run(name, solver, steps);
            println!(
                "{name:<20} {solver:<12} overlap {:>9.2e} ({:>3} steps)  energy {:>9.2e}  momentum {:>9}  collisions {:>6} pair {:>6} wall",
                o.max_overlap,
                o.longest_overlap_steps,
                o.energy_drift,
                o.momentum_drift.map_or("-".into(), |m| format!("{m:.2e}")),
                o.pair_collisions,
                o.wall_collisions
            );
            let what = format!("{name} under {solver}");
            assert_eq!(o.non_finite, 0, "{what}: non-finite state");
            assert_eq!(o.escaped, 0, "{what}: circles left the arena");
            let (overlap_bound, overlap_steps, energy_bound) = match solver {
                Solver::Exact => (ROUNDING, 0, 1e-9),
                Solver::Swept => (ROUNDING, 0, 1e-6),
                // A circle deflected within a step can press into one whose contact was only
                // foreseen as a pass-by, which the next step pushes out softly (measured in the
                // jammed packing: 0.027 to 0.056 as the time of impact's rounding changed, a
                // chaotic packing); resting contacts press for good.
                Solver::Soft(_) => (0.08, u32::MAX, soft_energy_bound(name)),
                // Overlaps in a chain of touching circles relax by diffusion under the one-pass
                // separation (measured: up to 32 steps in a row of 10).
                _ => (1.5, 60, 1e-6),
            };
            assert!(o.max_overlap <= overlap_bound, "{what}: overlap {:e} > {overlap_bound:e}", o.max_overlap);
            assert!(
                o.longest_overlap_steps <= overlap_steps,
                "{what}: a pair stayed overlapped for {} steps",
                o.longest_overlap_steps
            );
            assert!(o.energy_drift <= energy_bound, "{what}: energy drift {:e} > {energy_bound:e}", o.energy_drift);
            // What every solver promises at e = 1: energy is never gained. `soft` loses it where
            // contacts rest or hit below the restitution threshold, and bounds nothing else.
            assert!(o.energy_change <= 1e-9, "{what}: energy gained {:e}", o.energy_change);
            if let Some(m) = o.momentum_drift {
                assert!(m <= 1e-9, "{what}: momentum drift {m:e} in a step with no wall hit");
            }
            (solver, o)
        })
        .collect()
}

/// `Σ m v` of circles that move.
fn momentum_of(circles: &[CircleState]) -> DVec2 {
    circles
        .iter()
        .filter(|c| c.mass.is_finite())
        .map(|c| c.mass * c.velocity)
        .sum()
}

/// The energy `soft` may lose on case `name` at restitution 1, at 4 or 8 substeps (measured with `cargo test --test
/// suite hard_cases:: -- --nocapture`, 2026-12-06, and a margin): it solves a step's contacts
/// together, so where several meet in one step (a chain, a dense packing, many hits per circle
/// a step) the bounces share out less than the elastic hits would give; elsewhere it keeps the
/// energy to rounding.
fn soft_energy_bound(name: &str) -> f64 {
    match name {
        // 1755 circles at area fraction 0.86: every circle touches several (measured 0.67).
        "jammed.txt" => 0.75,
        // Five and ten circles touching in a row: the cradle's chain and the striker's row
        // (measured 0.31 and 0.36: a simultaneous solver shares the hit along the chain).
        "cradle.ron" => 0.35,
        "rounding_touch.ron" => 0.4,
        // Three arena widths a step: more hits a step than its 64 parts resolve (0.50 at 4
        // substeps, 0.62 at 8).
        "warp_speed.ron" => 0.7,
        // A one-second step, many hits in each part (0.063).
        "frame_spike.ron" => 0.08,
        // Crowded around a circle nearly the arena's size, or at a million units, where a
        // position's rounding is 1e-10 of a radius (0.027 and 0.015; 0.047 at 8 substeps).
        "huge_circle.ron" => 0.06,
        "far_offset.ron" => 0.02,
        // A ring that meets itself: three-body contacts (4.3e-5).
        "ring_self.ron" => 1e-4,
        _ => 1e-9,
    }
}

fn continuous(outcomes: &[(Solver, Outcome)]) -> impl Iterator<Item = &(Solver, Outcome)> {
    outcomes.iter().filter(|(s, _)| s.is_continuous())
}

#[test]
fn coincident_and_exactly_touching_centres() {
    suite("coincident.ron", 240);
    // The exactly touching pair (circles 4 and 5, closing at 2) trades velocities in the first
    // step under every solver (equal masses, e = 1); the other circles are far from them.
    for solver in SOLVERS {
        let o = run("coincident.ron", solver, 1);
        let (a, b) = (o.end[4].velocity, o.end[5].velocity);
        assert!(
            (a - DVec2::new(-1.0, 0.0)).length() < 1e-9
                && (b - DVec2::new(1.0, 0.0)).length() < 1e-9,
            "{solver}: the touching pair moves at {a} and {b}"
        );
    }
}

#[test]
fn touching_within_rounding_at_spawn() {
    // One second: the striker arrives at 0.4 s; the last circle reaches the wall at 1.4 s.
    let outcomes = suite("rounding_touch.ron", 60);
    // Under the event-driven solvers the row passes the striker's momentum down to the last
    // circle (the time-stepped ones share it along the row: not promised).
    for (solver, o) in continuous(&outcomes) {
        let last = o.end[9];
        assert!(
            (last.velocity - DVec2::new(1.0, 0.0)).length() < 1e-9,
            "{solver}: last circle: {}",
            last.velocity
        );
    }
}

#[test]
fn grazing_tangent_paths() {
    for (solver, o) in suite("grazing.ron", 600) {
        // Tangent contact has zero normal speed: no deflection beyond rounding. Tangency is
        // ill-conditioned (the deflection goes with the square root of the miss distance), so
        // rounding of 1e-16 can show as 1e-8: the bound is 1e-6.
        for k in [0, 1, 2] {
            let (a, b) = (o.start[k].velocity, o.end[k].velocity);
            assert!(
                (a.abs() - b.abs()).length() < 1e-6,
                "{solver}: circle {k} deflected: {a} → {b}"
            );
        }
    }
}

#[test]
fn head_on_at_eight_diameters_per_step() {
    let outcomes = suite("tunnelling.ron", 60);
    for (solver, o) in &outcomes {
        // `soft` splits a step into parts in which no circle moves more than a fraction of its
        // radius, so it catches what the event solvers catch; the course's method at 4
        // substeps still moves 2 diameters a substep and, as `discrete`, lets both pairs pass
        // through each other (not promised: docs/solvers.md).
        let caught = solver.is_continuous() || matches!(solver, Solver::Soft(_));
        let expected = if caught { 2 } else { 0 };
        assert_eq!(o.pair_collisions, expected, "{solver}: pairs that collide");
        assert_eq!(
            o.end[0].position.x < o.end[1].position.x,
            caught,
            "{solver}: the head-on pair passed through or not"
        );
    }
}

#[test]
fn a_45_degree_shot_into_a_corner() {
    for (solver, o) in suite("corner.ron", 300) {
        let v = o.end[0].velocity;
        assert_eq!(v.x.abs(), 3.0, "{solver}: {v}");
        assert_eq!(
            v.x, v.y,
            "{solver}: both walls reflect together, the path stays on the diagonal: {v}"
        );
        assert!(
            (o.end[0].position.x - o.end[0].position.y).abs() < 1e-9,
            "{solver}"
        );
    }
}

#[test]
fn newtons_cradle() {
    let outcomes = suite("cradle.ron", 120);
    for (solver, o) in continuous(&outcomes) {
        for (i, c) in o.end.iter().enumerate().take(4) {
            assert!(
                c.velocity.length() < 1e-12,
                "{solver}: row circle {i} moves: {}",
                c.velocity
            );
        }
        assert!(
            (o.end[4].velocity.x - 2.0).abs() < 1e-12,
            "{solver}: last circle {}",
            o.end[4].velocity
        );
    }
}

#[test]
fn a_jammed_packing_above_080() {
    let config = load("jammed.txt");
    let fraction = config
        .arena
        .area_fraction(config.circles.iter().map(|c| c.radius));
    assert!(fraction > 0.8, "area fraction {fraction}");
    suite("jammed.txt", 60);
}

#[test]
fn mass_ratio_one_to_a_million() {
    for (solver, o) in suite("mass_ratio.ron", 300) {
        assert!(o.pair_collisions >= 2, "{solver}");
        let heavy = o.end[0].velocity;
        assert!(
            (heavy - DVec2::new(0.1, 0.0)).length() < 1e-4,
            "{solver}: the heavy circle barely moves: {heavy}"
        );
    }
}

#[test]
fn radii_spanning_four_decades() {
    suite("radii_span.ron", 120);
}

#[test]
fn an_arena_a_million_units_from_the_origin() {
    suite("far_offset.ron", 240);
}

#[test]
fn a_one_second_frame_spike() {
    suite("frame_spike.ron", 30);
}

#[test]
fn a_microsecond_step() {
    for (solver, o) in suite("tiny_step.ron", 1000) {
        // 1000 µs at under 4 units/s: nothing moves more than 4 mm.
        for (a, b) in o.start.iter().zip(&o.end) {
            assert!(a.position.distance(b.position) <= 4e-3 + 1e-12, "{solver}");
        }
    }
}

#[test]
fn all_velocities_zero() {
    for (solver, o) in suite("at_rest.ron", 120) {
        assert_eq!(
            o.start.iter().map(|c| c.position).collect::<Vec<_>>(),
            o.end.iter().map(|c| c.position).collect::<Vec<_>>(),
            "{solver}"
        );
        assert_eq!(o.energy_drift, 0.0, "{solver}");
    }
}

#[test]
fn one_circle_nearly_as_large_as_the_arena() {
    suite("huge_circle.ron", 240);
}

#[test]
fn a_ring_collapsing_on_a_heavy_centre_stays_symmetric() {
    for (solver, o) in suite("ring.ron", 120) {
        // Every ring circle has the same speed and distance from the centre afterwards.
        let centre = o.end[0].position;
        let ring = &o.end[1..];
        let (d0, s0) = (ring[0].position.distance(centre), ring[0].velocity.length());
        for (k, c) in ring.iter().enumerate() {
            assert!(
                (c.position.distance(centre) - d0).abs() < 1e-6,
                "{solver}: circle {k} distance"
            );
            assert!(
                (c.velocity.length() - s0).abs() < 1e-6,
                "{solver}: circle {k} speed"
            );
        }
        assert_eq!(o.pair_collisions, 12, "{solver}: twelve hits");
    }
}

#[test]
fn a_ring_meeting_itself_conserves_what_it_must() {
    // Simultaneous three-body contacts are resolved pair by pair: conservation holds (checked
    // by the suite), symmetry is not promised.
    suite("ring_self.ron", 120);
}

#[test]
fn speeds_that_cross_the_arena_many_times_per_step() {
    for (solver, o) in suite("warp_speed.ron", 60) {
        // Equal circles all at 200: hits trade speeds, and the root mean square speed is the
        // energy's (kept by the solvers that promise it, lost in part by `soft`, above).
        let rms = |c: &[CircleState]| {
            (c.iter().map(|c| c.velocity.length_squared()).sum::<f64>() / c.len() as f64).sqrt()
        };
        assert!((rms(&o.start) - 200.0).abs() < 1e-9, "{solver}");
        if !matches!(solver, Solver::Soft(_)) {
            assert!(
                (rms(&o.end) - 200.0).abs() < 2e-4,
                "{solver}: {}",
                rms(&o.end)
            );
        }
        assert!(
            o.wall_collisions > 20 * 60,
            "{solver}: several wall hits per circle per step"
        );
    }
}
