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
    let mut pairs = Vec::new();
    overlapping_pairs(&mut CellList::default(), arena, circles, &mut pairs);
    pairs.retain(|&(i, j)| pair_meets(layers, i as usize, j as usize));
    pairs.sort_unstable();
    pairs
        .into_iter()
        .map(|(i, j)| {
            let (i, j) = (i as usize, j as usize);
            let ((p, r), (q, s)) = (circles[i], circles[j]);
            (i, j, r + s - arena.offset(p, q).length())
        })
        .collect()
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
        for (i, j, depth) in overlapping_circles(circles, arena, layers) {
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
        let (discs, mut layers): (Vec<_>, Vec<_>) =
            circles.map(|(p, r, layers)| ((p, r), layers)).unzip();
        if layers.iter().all(|&l| l == CollisionLayers::DEFAULT) {
            layers.clear();
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
