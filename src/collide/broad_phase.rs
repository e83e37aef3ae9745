//! Broad phase: a uniform cell list rebuilt every step by counting sort, so finding the
//! overlapping pairs of N circles costs O(N) instead of O(N²).
//!
//! Cells are at least as wide as the largest diameter, so two overlapping circles always sit in
//! the same or adjacent cells. Each pair is visited once by scanning a cell against itself and
//! four of its eight neighbours (the "half stencil").

use bevy::math::Vec2;

/// Circles bucketed by cell: `order[start[c]..start[c + 1]]` are the circles in cell `c`.
#[derive(Debug, Default, Clone)]
pub struct CellList {
    origin: Vec2,
    inv_cell: f32,
    cols: usize,
    rows: usize,
    start: Vec<u32>,
    order: Vec<u32>,
    cell_of: Vec<u32>,
}

/// No cell: the circle has a non-finite position and takes part in no pair.
const NO_CELL: u32 = u32::MAX;

impl CellList {
    /// Buckets `positions` into cells at least `min_cell` wide. The grid covers the bounding box
    /// of the finite positions, and never has more than about four cells per circle (a tiny
    /// radius in a huge box gets wider cells, which stays correct and bounds memory).
    pub fn rebuild(&mut self, positions: &[Vec2], min_cell: f32) {
        let n = positions.len();
        let (lo, hi) = positions
            .iter()
            .filter(|p| p.is_finite())
            .fold((Vec2::INFINITY, Vec2::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        let extent = if lo.x <= hi.x { hi - lo } else { Vec2::ZERO };
        let max_cells = (4 * n).max(1) as f32;
        let mut cell = min_cell.max(f32::MIN_POSITIVE);
        let fit = ((extent.x / cell).floor() + 1.0) * ((extent.y / cell).floor() + 1.0);
        if fit > max_cells || fit.is_nan() {
            cell = (extent.x * extent.y / max_cells)
                .sqrt()
                .max(extent.max_element() / max_cells)
                .max(cell);
        }
        self.origin = if lo.x <= hi.x { lo } else { Vec2::ZERO };
        self.inv_cell = 1.0 / cell;
        self.cols = ((extent.x * self.inv_cell).floor() as usize + 1).max(1);
        self.rows = ((extent.y * self.inv_cell).floor() as usize + 1).max(1);
        let cells = self.cols * self.rows;

        let mut cell_of = std::mem::take(&mut self.cell_of);
        cell_of.clear();
        cell_of.extend(positions.iter().map(|&p| self.cell_index(p)));
        self.cell_of = cell_of;
        self.start.clear();
        self.start.resize(cells + 1, 0);
        for &c in &self.cell_of {
            if c != NO_CELL {
                self.start[c as usize + 1] += 1;
            }
        }
        for c in 0..cells {
            self.start[c + 1] += self.start[c];
        }
        let placed = self.start[cells] as usize;
        self.order.clear();
        self.order.resize(placed, 0);
        let mut fill = self.start[..cells].to_vec();
        for (i, &c) in self.cell_of.iter().enumerate() {
            if c != NO_CELL {
                let slot = &mut fill[c as usize];
                self.order[*slot as usize] = i as u32;
                *slot += 1;
            }
        }
    }

    fn cell_index(&self, p: Vec2) -> u32 {
        if !p.is_finite() {
            return NO_CELL;
        }
        let c = (p - self.origin) * self.inv_cell;
        let x = (c.x.max(0.0) as usize).min(self.cols - 1);
        let y = (c.y.max(0.0) as usize).min(self.rows - 1);
        (y * self.cols + x) as u32
    }

    fn cell(&self, x: usize, y: usize) -> &[u32] {
        let c = y * self.cols + x;
        &self.order[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Calls `visit(i, j)` once for every pair of circles in the same or adjacent cells.
    pub fn for_each_candidate_pair(&self, mut visit: impl FnMut(u32, u32)) {
        for y in 0..self.rows {
            for x in 0..self.cols {
                let here = self.cell(x, y);
                for (k, &i) in here.iter().enumerate() {
                    for &j in &here[k + 1..] {
                        visit(i, j);
                    }
                }
                // Right, and the three cells of the row above: each neighbour pair once.
                let neighbours = [
                    (x + 1 < self.cols).then(|| (x + 1, y)),
                    (y + 1 < self.rows && x > 0).then(|| (x - 1, y + 1)),
                    (y + 1 < self.rows).then(|| (x, y + 1)),
                    (y + 1 < self.rows && x + 1 < self.cols).then(|| (x + 1, y + 1)),
                ];
                for (nx, ny) in neighbours.into_iter().flatten() {
                    let there = self.cell(nx, ny);
                    for &i in here {
                        for &j in there {
                            visit(i, j);
                        }
                    }
                }
            }
        }
    }
}

/// Appends to `pairs` every pair `(i, j)` of circles that overlap (centre distance below the
/// sum of radii), found through `cells`. The order depends only on the input, not on timing.
pub fn overlapping_pairs(
    cells: &mut CellList,
    positions: &[Vec2],
    radii: &[f32],
    pairs: &mut Vec<(u32, u32)>,
) {
    let max_radius = radii.iter().copied().fold(0.0f32, f32::max);
    cells.rebuild(positions, 2.0 * max_radius);
    cells.for_each_candidate_pair(|i, j| {
        let (a, b) = (i as usize, j as usize);
        let reach = radii[a] + radii[b];
        if positions[a].distance_squared(positions[b]) < reach * reach {
            pairs.push((i.min(j), i.max(j)));
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn brute_force(positions: &[Vec2], radii: &[f32]) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for i in 0..positions.len() {
            for j in i + 1..positions.len() {
                let reach = radii[i] + radii[j];
                if positions[i].distance_squared(positions[j]) < reach * reach {
                    pairs.push((i as u32, j as u32));
                }
            }
        }
        pairs
    }

    #[test]
    fn finds_exactly_the_pairs_brute_force_finds() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for (n, spread) in [(0, 1.0), (1, 1.0), (50, 1.0), (400, 10.0), (300, 1e4)] {
            let positions: Vec<Vec2> = (0..n)
                .map(|_| Vec2::new(rng.random_range(0.0..spread), rng.random_range(0.0..spread)))
                .collect();
            let radii: Vec<f32> = (0..n).map(|_| rng.random_range(0.01..0.3)).collect();
            let mut pairs = Vec::new();
            overlapping_pairs(&mut CellList::default(), &positions, &radii, &mut pairs);
            pairs.sort_unstable();
            assert_eq!(
                pairs,
                brute_force(&positions, &radii),
                "n = {n}, spread = {spread}"
            );
        }
    }

    #[test]
    fn non_finite_positions_take_part_in_no_pair() {
        let positions = [Vec2::ZERO, Vec2::new(f32::NAN, 0.0), Vec2::new(0.1, 0.0)];
        let mut pairs = Vec::new();
        overlapping_pairs(&mut CellList::default(), &positions, &[0.1; 3], &mut pairs);
        assert_eq!(pairs, vec![(0, 2)]);
    }
}
