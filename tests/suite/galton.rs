//! The Galton board scene (`assets/scenes/galton.ron`) headless: every dropped ball lands in a
//! bin, none escapes the board, none sinks into a peg, and the bins fill in a bell shape.

use std::path::Path;

use crate::common::*;
use bevy::math::DVec2;
use moving_circles::prelude::*;

/// The bin walls' x, left to right (the guides are the outer walls), and their top.
const BIN_EDGES: (f64, f64, usize) = (-5.2, 0.8, 14);
const BIN_TOP: f64 = -2.9;

/// Runs the board under `solver` with `balls` dropped, for `seconds`; returns the landed balls
/// per bin and the deepest a ball went into a peg over the run (in ball radii).
fn run_board(solver: &str, balls: usize, seconds: f64) -> (Vec<usize>, f64) {
    let mut config = Scene::load(Path::new("assets/scenes/galton.ron")).unwrap();
    config.solver = solver.parse().unwrap();
    let drop = config.drop.as_mut().unwrap();
    drop.count = balls;
    drop.every = 0.05;
    let mut app = create_app(config);
    let pegs: Vec<(DVec2, f64)> = circles(&mut app)
        .into_iter()
        .filter(|c| c.3.is_infinite())
        .map(|(p, _, r, _)| (p, r))
        .collect();
    assert_eq!(pegs.len(), 78);
    let steps = (seconds * 60.0) as u64;
    let mut deepest = f64::MIN;
    for _ in 0..steps {
        step(&mut app, 1);
        for (p, _, r, m) in circles(&mut app) {
            if m.is_finite() {
                for &(q, s) in &pegs {
                    deepest = deepest.max((r + s - p.distance(q)) / r);
                }
            }
        }
    }
    let landed: Vec<DVec2> = circles(&mut app)
        .into_iter()
        .filter(|c| c.3.is_finite())
        .map(|c| c.0)
        .collect();
    assert_eq!(landed.len(), balls, "{solver}: not every ball was dropped");
    let (left, width, walls) = BIN_EDGES;
    let right = left + width * (walls - 1) as f64;
    let mut bins = vec![0; walls - 1];
    for p in landed {
        assert!(
            p.y < BIN_TOP && p.x > left && p.x < right,
            "{solver}: a ball at {p} is not in a bin"
        );
        bins[((p.x - left) / width) as usize] += 1;
    }
    (bins, deepest)
}

#[test]
fn every_ball_lands_in_a_bin_clear_of_the_pegs_in_a_bell_shape() {
    // A discrete step can end with a ball pressed into a peg by the balls behind it (the one
    // contact pass resolves pairs in order); substeps shrink that, and the soft contacts hold
    // them off all but a fiftieth of a radius.
    for (solver, tolerance) in [("soft", 0.02), ("substeps=4", 0.1), ("discrete", 0.5)] {
        let (bins, deepest) = run_board(solver, 100, 25.0);
        eprintln!("{solver}: deepest into a peg {deepest:.3} radii, bins {bins:?}");
        assert!(
            deepest <= tolerance,
            "{solver}: a ball went {deepest} radii into a peg"
        );
        let middle: usize = bins[4..9].iter().sum();
        let outer: usize = bins[..2].iter().chain(&bins[11..]).sum();
        assert!(middle > 50 && outer < 15, "{solver}: not a bell: {bins:?}");
    }
}

#[test]
fn balls_land_exactly_under_the_continuous_solvers() {
    // The bins fill with small piles that must come to rest without a ball sinking into another
    // or the budget running out (inelastic collapse, held off by the contact time and sleeping:
    // docs/piles.md); 40 balls keep the test quick at the test build's optimisation.
    for solver in ["swept", "exact"] {
        let (bins, deepest) = run_board(solver, 40, 15.0);
        eprintln!("{solver}: deepest into a peg {deepest:.3e} radii, bins {bins:?}");
        assert!(
            deepest <= 1e-9,
            "{solver}: a ball went {deepest} radii into a peg"
        );
    }
}
