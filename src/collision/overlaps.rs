//! Overlap queries on a state: which pairs of circles overlap and by how much. Scene checks,
//! the run report, the accuracy study, the HUD and the hard-case tests all measure overlaps
//! through these, on the broad phase (so O(N)).

use bevy::math::DVec2;

use super::broad_phase::scan::fold_pairs_by_band;
use super::broad_phase::{CellList, needs_levels, overlapping_pairs, radius_range};
use crate::base::arena::Arena;
use crate::base::collision_layers::{CollisionLayers, pair_meets};

/// Every overlapping pair `(i, j, depth)` of `circles` (centre, radius), `i < j`, sorted, with
/// `depth` the overlap distance `r_i + r_j − |x_j − x_i|` in `arena`, among the pairs that
/// meet given each circle's `layers` (empty: every pair meets).
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::Arena;
/// use moving_circles::kernels::overlapping_circles;
///
/// let circles = [(DVec2::ZERO, 0.5), (DVec2::new(0.75, 0.0), 0.5)];
/// assert_eq!(overlapping_circles(&circles, &Arena::default(), &[]), [(0, 1, 0.25)]);
/// ```
pub fn overlapping_circles(
    circles: &[(DVec2, f64)],
    arena: &Arena,
    layers: &[CollisionLayers],
) -> Vec<(usize, usize, f64)> {
    overlaps_sorted(circles, arena, layers).collect()
}

/// [`overlapping_circles`] one pair at a time, without listing the depths.
fn overlaps_sorted<'a>(
    circles: &'a [(DVec2, f64)],
    arena: &'a Arena,
    layers: &[CollisionLayers],
) -> impl Iterator<Item = (usize, usize, f64)> + 'a {
    let mut pairs = Vec::new();
    overlapping_pairs(&mut CellList::default(), arena, circles, &mut pairs);
    pairs.retain(|&(i, j)| pair_meets(layers, i as usize, j as usize));
    pairs.sort_unstable();
    pairs.into_iter().map(|(i, j)| {
        let (i, j) = (i as usize, j as usize);
        let ((p, r), (q, s)) = (circles[i], circles[j]);
        (i, j, r + s - arena.offset(p, q).length())
    })
}

/// Overlaps in one or more states, each as a fraction of the pair's smaller radius.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Overlaps {
    /// Overlapping pairs.
    pub pairs: usize,
    /// Deepest overlap.
    pub max: f64,
    /// Sum of the overlaps (for a mean over pairs).
    pub sum: f64,
}

impl Overlaps {
    /// Measures the overlaps of `circles` (centre, radius) in `arena`, between the pairs that
    /// meet given each circle's `layers` (empty: every pair meets).
    ///
    /// Millions of overlapping pairs (what a run cut short by a signal leaves) are measured on
    /// all cores in bands of cells, without listing them; the bands are added up in row order,
    /// so the sum does not depend on the number of threads.
    pub fn measure(circles: &[(DVec2, f64)], arena: &Arena, layers: &[CollisionLayers]) -> Self {
        let range = radius_range(circles);
        let fraction = |(p, r): (DVec2, f64), (q, s): (DVec2, f64)| {
            (r + s - arena.offset(p, q).length()) / r.min(s)
        };
        let fold = |overlaps: &mut Self, (i, j), (a, b)| {
            if pair_meets(layers, i, j) {
                overlaps.count(fraction(a, b));
            }
        };
        let bands = match needs_levels(range) {
            false => fold_pairs_by_band(arena, circles, range.1, Self::default, fold),
            true => None,
        };
        let mut overlaps = Self::default();
        match bands {
            Some(bands) => bands.into_iter().for_each(|band| overlaps.add(band)),
            // Summed in the sorted pairs' order, whatever order the broad phase found them in.
            None => {
                for (i, j, _) in overlaps_sorted(circles, arena, layers) {
                    overlaps.count(fraction(circles[i], circles[j]));
                }
            }
        }
        overlaps
    }

    /// Counts one overlapping pair, overlapping by `fraction` of its smaller radius.
    fn count(&mut self, fraction: f64) {
        self.pairs += 1;
        self.max = self.max.max(fraction);
        self.sum += fraction;
    }

    /// [`Overlaps::measure`] of circles given as centre, radius and layers (as
    /// [`solver_layers`](crate::base::collision_layers::solver_layers) gives them).
    pub fn measure_layered(
        circles: impl Iterator<Item = (DVec2, f64, CollisionLayers)>,
        arena: &Arena,
    ) -> Self {
        let (mut discs, mut layers) = (Vec::with_capacity(circles.size_hint().0), Vec::new());
        for (p, r, own) in circles {
            // Layers listed from the first circle that has its own on (none: all meet).
            if !layers.is_empty() || own != CollisionLayers::DEFAULT {
                layers.resize(discs.len(), CollisionLayers::DEFAULT);
                layers.push(own);
            }
            discs.push((p, r));
        }
        Self::measure(&discs, arena, &layers)
    }

    /// Adds the overlaps of another state (deepest of both, sums added).
    pub fn add(&mut self, other: Overlaps) {
        self.pairs += other.pairs;
        self.max = self.max.max(other.max);
        self.sum += other.sum;
    }

    /// Mean overlap of the overlapping pairs (0 if there were none).
    pub fn mean(&self) -> f64 {
        if self.pairs == 0 {
            0.0
        } else {
            self.sum / self.pairs as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measure_counts_the_listed_pairs_and_their_deepest_overlap() {
        // On all cores in bands, and listed and sorted where the grid wraps onto itself (a
        // periodic box two cells wide): the same pairs and deepest overlap, the sum to rounding.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let ghost = CollisionLayers::new(0b10, 0b10);
        for (n, side) in [(12_000, 60.0), (40, 0.5)] {
            let circles: Vec<(DVec2, f64)> = (0..n)
                .map(|_| {
                    let p = DVec2::new(rng.random_range(0.0..side), rng.random_range(0.0..side));
                    (p, rng.random_range(0.05..0.25))
                })
                .collect();
            let layers: Vec<CollisionLayers> = (0..n)
                .map(|i| match i % 7 {
                    0 => ghost,
                    _ => CollisionLayers::DEFAULT,
                })
                .collect();
            let periodic = Arena {
                min: DVec2::ZERO,
                max: DVec2::splat(side),
                boundary: crate::base::arena::Boundary::Periodic,
            };
            for arena in [Arena::default(), periodic] {
                let listed = overlapping_circles(&circles, &arena, &layers);
                let fractions = listed
                    .iter()
                    .map(|&(i, j, depth)| depth / circles[i].1.min(circles[j].1));
                let max = fractions.clone().fold(0.0, f64::max);
                let sum: f64 = fractions.sum();
                let measured = Overlaps::measure(&circles, &arena, &layers);
                assert!(listed.len() > 10, "{}", listed.len());
                assert_eq!((measured.pairs, measured.max), (listed.len(), max));
                assert!(
                    (measured.sum - sum).abs() <= 1e-12 * sum,
                    "{measured:?}, {sum}"
                );
            }
        }
    }

    #[test]
    fn pairs_that_do_not_meet_are_not_counted_wherever_their_layers_start() {
        let ghost = CollisionLayers::new(0b10, 0b10);
        let arena = Arena::default();
        // Three circles in a row, each overlapping the next by 0.25.
        let at = |x: f64| (DVec2::new(x, 0.0), 0.5);
        let row = |layers: [CollisionLayers; 3]| {
            let circles = [0.0, 0.75, 1.5].map(at);
            let measured = circles.iter().zip(layers).map(|(&(p, r), l)| (p, r, l));
            Overlaps::measure_layered(measured, &arena).pairs
        };
        let plain = CollisionLayers::DEFAULT;
        assert_eq!(row([plain; 3]), 2);
        assert_eq!(row([plain, plain, ghost]), 1);
        assert_eq!(row([ghost, plain, plain]), 1);
        assert_eq!(row([plain, ghost, plain]), 0);
        assert_eq!(row([ghost, ghost, CollisionLayers::ALL]), 2);
    }
}
