//! Broad phase: which circles overlap, in O(N) instead of O(N²). Circles of similar size are
//! binned into a uniform cell list ([`cells`]) rebuilt every step by counting sort and scanned
//! once per pair with a half stencil ([`scan`], parallel over bands of rows); radii spanning
//! more than [`MULTI_LEVEL_RATIO`] get one grid per size level (`levels`).
//!
//! Cells are at least as wide as the largest diameter, so two overlapping circles always sit in
//! the same or adjacent cells. The input is `(centre, reach)` per circle: the radius, or for
//! swept tests the radius grown by the distance moved.

pub mod cells;
mod levels;
pub mod scan;

use std::ops::ControlFlow;

use bevy::math::DVec2;

use crate::base::arena::Arena;
pub use cells::{CellList, radius_range};
pub use scan::pairs_in_cell_order;

/// Radius ratio (largest / smallest) above which [`overlapping_pairs`] sorts circles into
/// levels of similar size, each with its own grid.
pub const MULTI_LEVEL_RATIO: f64 = 8.0;

/// Whether radii from `r_min` to `r_max` span more than [`MULTI_LEVEL_RATIO`], so that one grid
/// would be slow.
pub fn needs_levels((r_min, r_max): (f64, f64)) -> bool {
    r_min > 0.0 && r_max > MULTI_LEVEL_RATIO * r_min
}

/// Appends to `pairs` every pair `(i, j)`, `i < j`, of `circles` (centre, reach) that overlap
/// in `arena` (centre distance below the sum of reaches; the minimum image on a periodic
/// arena). The order depends only on the input, not on the number of threads.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::Arena;
/// use moving_circles::kernels::{CellList, overlapping_pairs};
///
/// let circles = [(DVec2::ZERO, 0.5), (DVec2::new(0.9, 0.0), 0.5), (DVec2::new(3.0, 0.0), 0.5)];
/// let mut pairs = Vec::new();
/// overlapping_pairs(&mut CellList::default(), &Arena::default(), &circles, &mut pairs);
/// assert_eq!(pairs, [(0, 1)]);
/// ```
pub fn overlapping_pairs(
    cells: &mut CellList,
    arena: &Arena,
    circles: &[(DVec2, f64)],
    pairs: &mut Vec<(u32, u32)>,
) {
    let (r_min, r_max) = radius_range(circles);
    if needs_levels((r_min, r_max)) {
        levels::multi_level_pairs(arena, circles, r_min, pairs);
    } else {
        scan::single_level_pairs(cells, arena, circles, r_max, pairs);
    }
}

/// Hands every pair `(i, j)`, `i < j`, of `circles` (centre, reach) that overlaps in `arena` to
/// `visit` until it returns [`ControlFlow::Break`], serially and without listing the pairs:
/// memory stays O(N) however many pairs overlap, so a check can stop at the first bad pair of
/// a hostile input. A pair may come twice on a periodic arena only a few cells wide.
///
/// ```
/// use std::ops::ControlFlow;
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::Arena;
/// use moving_circles::kernels::visit_overlapping_pairs;
///
/// // 1000 circles at one point overlap in 499 500 pairs; the visit stops after the first.
/// let circles = vec![(DVec2::ZERO, 0.5); 1000];
/// let mut seen = 0;
/// let _ = visit_overlapping_pairs(&Arena::default(), &circles, |_, _| {
///     seen += 1;
///     ControlFlow::Break(())
/// });
/// assert_eq!(seen, 1);
/// ```
pub fn visit_overlapping_pairs(
    arena: &Arena,
    circles: &[(DVec2, f64)],
    mut visit: impl FnMut(usize, usize) -> ControlFlow<()>,
) -> ControlFlow<()> {
    let (r_min, r_max) = radius_range(circles);
    let mut visit = |i: u32, j: u32| visit(i as usize, j as usize);
    if needs_levels((r_min, r_max)) {
        levels::visit_multi_level(arena, circles, r_min, &mut visit)
    } else {
        scan::visit_single_level(&mut CellList::default(), arena, circles, r_max, &mut visit)
    }
}

#[cfg(test)]
mod tests {
    use super::cells::PARALLEL_FROM;
    use super::*;
    use crate::base::arena::Boundary;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The broad phase's pairs, sorted, checked against brute force, and the same pairs seen
    /// by the visit.
    fn pairs_checked(arena: Arena, positions: &[DVec2], radii: &[f64]) -> Vec<(u32, u32)> {
        let circles: Vec<(DVec2, f64)> = positions
            .iter()
            .copied()
            .zip(radii.iter().copied())
            .collect();
        let mut pairs = Vec::new();
        overlapping_pairs(&mut CellList::default(), &arena, &circles, &mut pairs);
        pairs.sort_unstable();
        assert_eq!(
            pairs,
            brute_force(&arena, &circles),
            "{arena:?}, n = {}",
            positions.len()
        );
        let mut visited = Vec::new();
        let _ = visit_overlapping_pairs(&arena, &circles, |i, j| {
            assert!(i < j);
            visited.push((i as u32, j as u32));
            ControlFlow::Continue(())
        });
        visited.sort_unstable();
        visited.dedup();
        assert_eq!(visited, pairs, "visit, {arena:?}, n = {}", positions.len());
        pairs
    }

    fn brute_force(arena: &Arena, circles: &[(DVec2, f64)]) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for (i, &(p, r)) in circles.iter().enumerate() {
            for (j, &(q, s)) in circles.iter().enumerate().skip(i + 1) {
                if arena.offset(p, q).length_squared() < (r + s) * (r + s) {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
        pairs
    }

    fn periodic_arena(min: DVec2, size: DVec2) -> Arena {
        Arena {
            min,
            max: min + size,
            boundary: Boundary::Periodic,
        }
    }

    #[test]
    fn finds_exactly_the_pairs_brute_force_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for (n, spread) in [(0, 1.0), (1, 1.0), (50, 1.0), (400, 10.0), (300, 1e4)] {
            let positions: Vec<DVec2> = (0..n)
                .map(|_| DVec2::new(rng.random_range(0.0..spread), rng.random_range(0.0..spread)))
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.01..0.3)).collect();
            pairs_checked(Arena::default(), &positions, &radii);
        }
    }

    #[test]
    fn periodic_pairs_across_the_seam_are_found_once() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let mut seam_pairs = 0;
        // Box sizes from one cell per axis (every neighbour is the cell itself) to many.
        for (n, side, r_max) in [
            (40, 1.0, 0.3),
            (60, 1.0, 0.2),
            (300, 4.0, 0.15),
            (500, 10.0, 0.1),
        ] {
            let size = DVec2::new(side, side * 0.75);
            let min = DVec2::new(-1.0, 2.0);
            let space = periodic_arena(min, size);
            let positions: Vec<DVec2> = (0..n)
                .map(|_| {
                    min + DVec2::new(rng.random_range(0.0..size.x), rng.random_range(0.0..size.y))
                })
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.01..r_max)).collect();
            let expected = pairs_checked(space, &positions, &radii);
            seam_pairs += expected
                .iter()
                .filter(|&&(i, j)| {
                    (positions[i as usize] - positions[j as usize]).length() > size.x / 2.0
                })
                .count();
        }
        assert!(
            seam_pairs > 0,
            "the cases should include pairs across the seam"
        );
    }

    #[test]
    fn the_parallel_scan_gives_the_sequential_result_in_the_same_order() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let n = 3 * PARALLEL_FROM;
        let positions: Vec<DVec2> = (0..n)
            .map(|_| DVec2::new(rng.random_range(0.0..60.0), rng.random_range(0.0..40.0)))
            .collect();
        let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.05..0.3)).collect();
        let circles: Vec<(DVec2, f64)> = positions.into_iter().zip(radii).collect();
        for arena in [
            Arena::default(),
            periodic_arena(DVec2::ZERO, DVec2::new(60.0, 40.0)),
        ] {
            let mut cells = CellList::default();
            let mut parallel = Vec::new();
            overlapping_pairs(&mut cells, &arena, &circles, &mut parallel);
            // One band over all rows: what a single thread does.
            let mut sequential = Vec::new();
            let rows = cells.grid.rows;
            scan::scan_rows(&cells, &cells.sorted, &arena, 0..rows, &mut sequential);
            for pair in &mut sequential {
                *pair = (cells.order[pair.0 as usize], cells.order[pair.1 as usize]);
            }
            assert!(parallel.len() > 1000, "{}", parallel.len());
            assert_eq!(parallel, sequential);
        }
    }

    #[test]
    fn the_bands_folded_hold_the_listed_pairs_in_the_listed_order() {
        // Serial (few circles) and on all cores: the bands, joined in row order, hold exactly
        // the pairs `overlapping_pairs` lists, in its order, so what is folded per band and
        // the order the bands are added in do not depend on the threads.
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        for n in [300, 3 * PARALLEL_FROM] {
            let side = (n as f64 / 3.0).sqrt();
            let circles: Vec<(DVec2, f64)> = (0..n)
                .map(|_| {
                    let p = DVec2::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
                    (p, rng.random_range(0.05..0.3))
                })
                .collect();
            for arena in [
                Arena::default(),
                periodic_arena(DVec2::ZERO, DVec2::splat(side)),
            ] {
                let mut listed = Vec::new();
                overlapping_pairs(&mut CellList::default(), &arena, &circles, &mut listed);
                let r_max = radius_range(&circles).1;
                let fold = |band: &mut Vec<(u32, u32)>, (i, j): (usize, usize), (a, b)| {
                    assert_eq!((a, b), (circles[i], circles[j]));
                    band.push((i as u32, j as u32));
                };
                let bands = scan::fold_pairs_by_band(&arena, &circles, r_max, Vec::new, fold);
                let bands = bands.expect("a grid many cells wide");
                assert!(listed.len() > 100, "{}", listed.len());
                assert!(
                    n < PARALLEL_FROM || bands.len() > 1,
                    "{} bands",
                    bands.len()
                );
                assert_eq!(bands.concat(), listed, "n = {n}, {arena:?}");
            }
        }
    }

    #[test]
    fn radii_spanning_decades_find_exactly_the_brute_force_pairs() {
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        for periodic in [false, true] {
            let size = DVec2::new(1.0, 0.8);
            let space = if periodic {
                periodic_arena(DVec2::ZERO, size)
            } else {
                Arena::default()
            };
            let n = 1500;
            let positions: Vec<DVec2> = (0..n)
                .map(|_| DVec2::new(rng.random_range(0.0..size.x), rng.random_range(0.0..size.y)))
                .collect();
            // Radii log-uniform over 1e-4 .. 1e-1: four decades, several levels.
            let radii: Vec<f64> = (0..n)
                .map(|_| 10f64.powf(rng.random_range(-4.0..-1.0)))
                .collect();
            let expected = pairs_checked(space, &positions, &radii);
            assert!(expected.len() > 50, "{}", expected.len());
        }
    }

    #[test]
    fn radii_across_the_whole_f64_range_neither_panic_nor_miss_a_pair() {
        // Subnormal beside normal: the ratio of radii overflows to infinity.
        let radii = [5e-324, 1e-310, 1e-200, 1e-3, 0.25, 0.5];
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let positions: Vec<DVec2> = (0..300)
            .map(|_| DVec2::new(rng.random_range(0.0..4.0), rng.random_range(0.0..4.0)))
            .collect();
        let radii: Vec<f64> = (0..300).map(|i| radii[i % radii.len()]).collect();
        let expected = pairs_checked(Arena::default(), &positions, &radii);
        assert!(!expected.is_empty());
    }

    #[test]
    fn non_finite_positions_take_part_in_no_pair() {
        let circles = [
            (DVec2::ZERO, 0.1),
            (DVec2::new(f64::NAN, 0.0), 0.1),
            (DVec2::new(0.1, 0.0), 0.1),
        ];
        let mut pairs = Vec::new();
        overlapping_pairs(
            &mut CellList::default(),
            &Arena::default(),
            &circles,
            &mut pairs,
        );
        assert_eq!(pairs, vec![(0, 2)]);
    }

    #[test]
    fn a_cell_list_used_again_forgets_the_last_circles() {
        // The cell list keeps its tables from one rebuild to the next without refilling them:
        // shrinking, growing, the same count on another grid, and with circles that take part
        // in nothing (non-finite), each rebuild finds what a new list finds. Radii within a
        // factor of 2, so one grid (the kept list) does the work; the two larger inputs are
        // longer than one chunk of the parallel folds.
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        let mut kept = CellList::default();
        for (n, spread) in [
            (40_000, 250.0),
            (600, 30.0),
            (50_000, 150.0),
            (9_000, 120.0),
        ] {
            let mut circles: Vec<(DVec2, f64)> = (0..n)
                .map(|_| {
                    let p =
                        DVec2::new(rng.random_range(0.0..spread), rng.random_range(0.0..spread));
                    (p, rng.random_range(0.3..0.6))
                })
                .collect();
            for i in (0..n).step_by(97) {
                circles[i].0.x = f64::NAN;
            }
            let serial = circles.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
                (lo.min(c.1), hi.max(c.1))
            });
            assert_eq!(radius_range(&circles), serial, "n = {n}");
            for arena in [
                Arena::default(),
                periodic_arena(DVec2::ZERO, DVec2::splat(spread)),
            ] {
                let (mut again, mut new) = (Vec::new(), Vec::new());
                let mut fresh = CellList::default();
                overlapping_pairs(&mut kept, &arena, &circles, &mut again);
                overlapping_pairs(&mut fresh, &arena, &circles, &mut new);
                assert!(!new.is_empty(), "n = {n}");
                assert_eq!(again, new, "n = {n}, {arena:?}");
                assert_eq!(kept.order().len(), n - n.div_ceil(97), "n = {n}");
                assert_eq!(kept.order(), fresh.order(), "n = {n}, {arena:?}");
                assert_eq!(kept.sorted, fresh.sorted, "n = {n}, {arena:?}");
                assert_eq!(kept.grid(), fresh.grid(), "n = {n}, {arena:?}");
            }
        }
    }
}
