//! Overlap queries on a state: which pairs of circles overlap and by how much. Scene checks,
//! the run report, the accuracy study, the HUD and the hard-case tests all measure overlaps
//! through these, on the broad phase (so O(N)).

use bevy::math::DVec2;

use super::broad_phase::{CellList, overlapping_pairs};
use crate::arena::Arena;
use crate::collision_layers::{CollisionLayers, pair_meets};

/// Every overlapping pair `(i, j, depth)` of `circles` (centre, radius), `i < j`, sorted, with
/// `depth` the overlap distance `r_i + r_j − |x_j − x_i|` in `arena`, among the pairs that
/// meet given each circle's `layers` (empty: every pair meets).
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::arena::Arena;
/// use moving_circles::collide::overlaps::overlapping_circles;
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
    pub fn measure(circles: &[(DVec2, f64)], arena: &Arena, layers: &[CollisionLayers]) -> Self {
        let mut overlaps = Self::default();
        // Summed in the sorted pairs' order, whatever order the broad phase found them in.
        for (i, j, depth) in overlaps_sorted(circles, arena, layers) {
            let fraction = depth / circles[i].1.min(circles[j].1);
            overlaps.pairs += 1;
            overlaps.max = overlaps.max.max(fraction);
            overlaps.sum += fraction;
        }
        overlaps
    }

    /// [`Overlaps::measure`] of circles given as centre, radius and layers (as
    /// [`solver_layers`](crate::collision_layers::solver_layers) gives them).
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
