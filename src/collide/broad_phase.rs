//! Broad phase: a uniform cell list rebuilt every step by counting sort, so finding the
//! overlapping pairs of N circles costs O(N) instead of O(N²).
//!
//! Cells are at least as wide as the largest diameter, so two overlapping circles always sit in
//! the same or adjacent cells. Each pair is visited once by scanning a cell against itself and
//! four of its eight neighbours (the "half stencil").

use bevy::math::DVec2;
use bevy::tasks::{ComputeTaskPool, ParallelSliceMut, TaskPool};

/// A circle as the broad phase sees it: `(centre, radius)`.
pub type Disc = (DVec2, f64);

/// Circles bucketed by cell: `order[start[c]..start[c + 1]]` are the circles in cell `c`.
#[derive(Debug, Default, Clone)]
pub struct CellList {
    periodic: bool,
    origin: DVec2,
    inv_cell: f64,
    cols: usize,
    rows: usize,
    /// Cell height relative to width is `1 / y_scale` (1 unless periodic tiling needs otherwise).
    y_scale: f64,
    start: Vec<u32>,
    order: Vec<u32>,
    cell_of: Vec<u32>,
    /// Next free slot per cell while filling `order`.
    cursor: Vec<u32>,
    /// Positions and radii in `order`, reused by [`overlapping_pairs`].
    sorted: Vec<(DVec2, f64)>,
}

/// No cell: the circle has a non-finite position and takes part in no pair.
const NO_CELL: u32 = u32::MAX;

impl CellList {
    /// Buckets `positions` into cells at least `min_cell` wide. The grid covers the bounding box
    /// of the finite positions, and never has more than about four cells per circle (a tiny
    /// radius in a huge box gets wider cells, which stays correct and bounds memory).
    pub fn rebuild(&mut self, circles: &[Disc], min_cell: f64) {
        let n = circles.len();
        let (lo, hi) = circles
            .iter()
            .map(|c| c.0)
            .filter(|p| p.is_finite())
            .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let extent = if lo.x <= hi.x { hi - lo } else { DVec2::ZERO };
        let max_cells = (4 * n).max(1) as f64;
        let mut cell = min_cell.max(f64::MIN_POSITIVE);
        let fit = ((extent.x / cell).floor() + 1.0) * ((extent.y / cell).floor() + 1.0);
        if fit > max_cells || fit.is_nan() {
            cell = (extent.x * extent.y / max_cells)
                .sqrt()
                .max(extent.max_element() / max_cells)
                .max(cell);
        }
        self.periodic = false;
        self.origin = if lo.x <= hi.x { lo } else { DVec2::ZERO };
        self.inv_cell = 1.0 / cell;
        self.y_scale = 1.0;
        self.cols = ((extent.x * self.inv_cell).floor() as usize + 1).max(1);
        self.rows = ((extent.y * self.inv_cell).floor() as usize + 1).max(1);
        self.fill(circles);
    }

    /// Buckets `positions` (already wrapped into the periodic box at `min` of this `size`) into
    /// a grid that tiles the box exactly, with cells at least `min_cell` wide.
    pub fn rebuild_periodic(&mut self, circles: &[Disc], min: DVec2, size: DVec2, min_cell: f64) {
        let max_per_axis = ((4 * circles.len()).max(1) as f64).sqrt().ceil();
        let per_axis = |length: f64| {
            let n = (length / min_cell.max(f64::MIN_POSITIVE)).floor();
            (n.min(max_per_axis) as usize).max(1)
        };
        self.periodic = true;
        self.origin = min;
        self.cols = per_axis(size.x);
        self.rows = per_axis(size.y);
        // Cells may be non-square here; `inv_cell` is per x, and y is rescaled by the ratio.
        self.inv_cell = self.cols as f64 / size.x;
        self.y_scale = (self.rows as f64 / size.y) / self.inv_cell;
        self.fill(circles);
    }

    /// Whether the periodic grid is too coarse for the wrapped half stencil to visit each
    /// neighbour cell once (fewer than three cells on an axis).
    pub fn wraps_onto_itself(&self) -> bool {
        self.periodic && (self.cols < 3 || self.rows < 3)
    }

    /// The circles' input indices in cell order (circles with a non-finite centre left out).
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    fn fill(&mut self, circles: &[Disc]) {
        let cells = self.cols * self.rows;

        let mut cell_of = std::mem::take(&mut self.cell_of);
        cell_of.clear();
        cell_of.resize(circles.len(), NO_CELL);
        let this = &*self;
        map_chunks(&mut cell_of, |from, out| {
            for (cell, c) in out.iter_mut().zip(&circles[from..]) {
                *cell = this.cell_index(c.0);
            }
        });
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
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.start[..cells]);
        for (i, &c) in self.cell_of.iter().enumerate() {
            if c != NO_CELL {
                let slot = &mut self.cursor[c as usize];
                self.order[*slot as usize] = i as u32;
                *slot += 1;
            }
        }
    }

    fn cell_index(&self, p: DVec2) -> u32 {
        if !p.is_finite() {
            return NO_CELL;
        }
        let mut c = (p - self.origin) * self.inv_cell;
        if self.periodic {
            c.y *= self.y_scale;
        }
        let x = (c.x.max(0.0) as usize).min(self.cols - 1);
        let y = (c.y.max(0.0) as usize).min(self.rows - 1);
        (y * self.cols + x) as u32
    }

    /// Calls `visit(k)` for every circle (as its position `k` in the cell order) in the cells
    /// that the box `[lo, hi]` touches; on a periodic grid the box wraps around.
    pub fn for_each_in_box(&self, lo: DVec2, hi: DVec2, mut visit: impl FnMut(usize)) {
        let to_cell = |p: DVec2| {
            let mut c = (p - self.origin) * self.inv_cell;
            if self.periodic {
                c.y *= self.y_scale;
            }
            c.floor()
        };
        let (a, b) = (to_cell(lo), to_cell(hi));
        let axis = |from: f64, to: f64, count: usize| -> Vec<usize> {
            if !(from.is_finite() && to.is_finite()) {
                return Vec::new();
            }
            if self.periodic {
                if to - from + 1.0 >= count as f64 {
                    return (0..count).collect();
                }
                (from as i64..=to as i64)
                    .map(|c| c.rem_euclid(count as i64) as usize)
                    .collect()
            } else {
                let clamp = |c: f64| (c.max(0.0) as usize).min(count - 1);
                (clamp(from)..=clamp(to)).collect()
            }
        };
        let xs = axis(a.x, b.x, self.cols);
        for y in axis(a.y, b.y, self.rows) {
            for &x in &xs {
                self.range(x, y).for_each(&mut visit);
            }
        }
    }

    /// Positions in [`Self::order`] of the circles in cell `(x, y)`.
    fn range(&self, x: usize, y: usize) -> std::ops::Range<usize> {
        let c = y * self.cols + x;
        self.start[c] as usize..self.start[c + 1] as usize
    }

    /// On a periodic grid, the circles (as ranges of positions in [`Self::order`]) that a
    /// circle of cell `(x, y)` is tested against: its own cell (the caller skips up to itself)
    /// and the "half stencil" (the cell to the right and the three above), wrapped around the
    /// seams. Ranges that meet are merged. (The open grid's two ranges are written out in
    /// [`scan_rows_with`].)
    fn periodic_later_neighbours(
        &self,
        x: usize,
        y: usize,
    ) -> ([std::ops::Range<usize>; 5], usize) {
        let (cols, rows) = (self.cols, self.rows);
        let at = |x: usize, y: usize| self.start[y * cols + x] as usize;
        let end = |x: usize, y: usize| self.start[y * cols + x + 1] as usize;
        let mut ranges: [std::ops::Range<usize>; 5] = Default::default();
        let mut len = 0;
        let mut add = |r: std::ops::Range<usize>| {
            if len > 0 && ranges[len - 1].end == r.start {
                ranges[len - 1].end = r.end;
            } else if !r.is_empty() {
                ranges[len] = r;
                len += 1;
            }
        };
        let (right, left, up) = ((x + 1) % cols, (x + cols - 1) % cols, (y + 1) % rows);
        add(at(x, y)..end(x, y));
        add(at(right, y)..end(right, y));
        for cx in [left, x, right] {
            add(at(cx, up)..end(cx, up));
        }
        (ranges, len)
    }
}

/// The space the circles live in, as far as distances go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Space {
    /// Plain Euclidean distances.
    Open,
    /// A periodic box at `min` of this `size`: distances use the minimum image.
    Periodic {
        /// Lower-left corner.
        min: DVec2,
        /// Width and height.
        size: DVec2,
    },
}

impl Space {
    /// The displacement from `a` to `b` (the minimum image on a periodic box).
    #[inline]
    pub fn offset(self, a: DVec2, b: DVec2) -> DVec2 {
        match self {
            Space::Open => b - a,
            Space::Periodic { size, .. } => crate::boundary::minimum_image(b - a, size),
        }
    }
}

/// Circle count from which the pair scan and the per-circle passes run on all cores.
pub const PARALLEL_FROM: usize = 4_000;

/// Fills `out` by calling `fill(offset, chunk)` on chunks of it, on all cores when it is long
/// (each element depends only on its index, so the result does not depend on the threads).
fn map_chunks<T: Send>(mut out: &mut [T], fill: impl Fn(usize, &mut [T]) + Send + Sync) {
    const CHUNK: usize = 1 << 14;
    if out.len() < PARALLEL_FROM {
        fill(0, out);
        return;
    }
    let pool = ComputeTaskPool::get_or_init(TaskPool::default);
    out.par_chunk_map_mut(pool, CHUNK, |index, chunk| fill(index * CHUNK, chunk));
}

/// Scans the cells of `rows`, appending overlapping pairs: per circle (in cell order), the rest
/// of its own cell, then the half stencil's cells. Visiting circles rather than cells skips the
/// empty cells, which outnumber circles in a sparse gas.
fn scan_rows(
    cells: &CellList,
    sorted: &[Disc],
    space: Space,
    rows: std::ops::Range<usize>,
    pairs: &mut Vec<(u32, u32)>,
) {
    match space {
        Space::Open => scan_rows_with(cells, sorted, |a, b| b - a, rows, pairs),
        Space::Periodic { size, .. } => scan_rows_with(
            cells,
            sorted,
            |a, b| crate::boundary::minimum_image(b - a, size),
            rows,
            pairs,
        ),
    }
}

/// [`scan_rows`] with the displacement function fixed at compile time.
fn scan_rows_with(
    cells: &CellList,
    sorted: &[Disc],
    offset: impl Fn(DVec2, DVec2) -> DVec2,
    rows: std::ops::Range<usize>,
    pairs: &mut Vec<(u32, u32)>,
) {
    let (cols, start) = (cells.cols, &cells.start);
    for y in rows {
        let row = y * cols;
        for x in 0..cols {
            let here = start[row + x] as usize..start[row + x + 1] as usize;
            if here.is_empty() {
                continue;
            }
            let (ranges, len) = if cells.periodic {
                cells.periodic_later_neighbours(x, y)
            } else {
                // Open grid, written out: own and right cell, then the three cells above.
                let right = (x + 1).min(cols - 1);
                let mut ranges: [std::ops::Range<usize>; 5] = Default::default();
                ranges[0] = here.start..start[row + right + 1] as usize;
                if y + 1 < cells.rows {
                    let up = row + cols;
                    ranges[1] =
                        start[up + x.saturating_sub(1)] as usize..start[up + right + 1] as usize;
                }
                (ranges, 2)
            };
            for k in here.clone() {
                let (p, r) = sorted[k];
                for range in &ranges[..len] {
                    // Within its own cell a circle meets only the ones after it.
                    let from = if range.contains(&k) {
                        k + 1
                    } else {
                        range.start
                    };
                    for (l, &(q, s)) in sorted[from..range.end].iter().enumerate() {
                        let reach = r + s;
                        if offset(p, q).length_squared() < reach * reach {
                            let (k, l) = (k as u32, (from + l) as u32);
                            // Oriented so the first has the lower input index.
                            let lower_first = cells.order[k as usize] < cells.order[l as usize];
                            pairs.push(if lower_first { (k, l) } else { (l, k) });
                        }
                    }
                }
            }
        }
    }
}

/// Radius ratio (largest / smallest) above which [`overlapping_pairs`] sorts circles into
/// levels of similar size, each with its own grid: one grid sized for the largest circle would
/// put thousands of small circles in each cell.
pub const MULTI_LEVEL_RATIO: f64 = 8.0;

/// The smallest and largest radius (`(∞, 0)` for no circles), in one pass.
pub fn radius_range(circles: &[Disc]) -> (f64, f64) {
    circles.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
        (lo.min(c.1), hi.max(c.1))
    })
}

/// Whether radii from `r_min` to `r_max` span more than [`MULTI_LEVEL_RATIO`], so that one grid
/// would be slow.
pub fn needs_levels((r_min, r_max): (f64, f64)) -> bool {
    r_min > 0.0 && r_max > MULTI_LEVEL_RATIO * r_min
}

/// Appends to `pairs` every pair `(i, j)`, `i < j`, of circles that overlap (centre distance
/// below the sum of radii). The order depends only on the input, not on the number of threads.
///
/// Circles of similar size share one uniform grid (`cells`); when radii span more than
/// [`MULTI_LEVEL_RATIO`], circles are split into levels by size (a factor of 4 per level), each
/// level gets its own grid, and each circle also checks the cells of the finer levels under it.
pub fn overlapping_pairs(
    cells: &mut CellList,
    space: Space,
    positions: &[DVec2],
    radii: &[f64],
    pairs: &mut Vec<(u32, u32)>,
) {
    let circles: Vec<(DVec2, f64)> = positions
        .iter()
        .copied()
        .zip(radii.iter().copied())
        .collect();
    pairs_among(cells, space, &circles, pairs);
}

/// [`overlapping_pairs`] of `(centre, radius)` circles.
pub fn pairs_among(
    cells: &mut CellList,
    space: Space,
    circles: &[Disc],
    pairs: &mut Vec<(u32, u32)>,
) {
    let (r_min, r_max) = radius_range(circles);
    if needs_levels((r_min, r_max)) {
        multi_level_pairs(space, circles, r_min, pairs);
    } else {
        single_level_pairs(cells, space, circles, r_max, pairs);
    }
}

/// [`pairs_in_cell_order`] translated back to input indices.
fn single_level_pairs(
    cells: &mut CellList,
    space: Space,
    circles: &[Disc],
    max_radius: f64,
    pairs: &mut Vec<(u32, u32)>,
) {
    let start = pairs.len();
    let mut sorted = std::mem::take(&mut cells.sorted);
    pairs_in_cell_order(cells, space, circles, max_radius, &mut sorted, pairs);
    cells.sorted = sorted;
    for pair in &mut pairs[start..] {
        *pair = (cells.order[pair.0 as usize], cells.order[pair.1 as usize]);
    }
}

fn multi_level_pairs(
    space: Space,
    circles: &[(DVec2, f64)],
    r_min: f64,
    pairs: &mut Vec<(u32, u32)>,
) {
    let level_of = |r: f64| ((r / r_min).log2() / 2.0).floor().max(0.0) as usize;
    let mut members: Vec<Vec<u32>> = Vec::new();
    for (i, &(_, r)) in circles.iter().enumerate() {
        let l = level_of(r);
        if members.len() <= l {
            members.resize(l + 1, Vec::new());
        }
        members[l].push(i as u32);
    }
    struct Level {
        members: Vec<u32>,
        cells: CellList,
        max_radius: f64,
    }
    let mut levels: Vec<Level> = Vec::with_capacity(members.len());
    let start = pairs.len();
    for members in members {
        let own: Vec<(DVec2, f64)> = members.iter().map(|&i| circles[i as usize]).collect();
        let mut cells = CellList::default();
        let mut local = Vec::new();
        let max_radius = radius_range(&own).1;
        single_level_pairs(&mut cells, space, &own, max_radius, &mut local);
        pairs.extend(local.into_iter().map(|(a, b)| {
            let (i, j) = (members[a as usize], members[b as usize]);
            (i.min(j), i.max(j))
        }));
        levels.push(Level {
            members,
            cells,
            max_radius,
        });
    }
    // Each circle against the finer levels: the cells its reach could touch.
    for (m, coarse) in levels.iter().enumerate() {
        for &a in &coarse.members {
            let (p, r) = circles[a as usize];
            for fine in &levels[..m] {
                if fine.members.is_empty() {
                    continue;
                }
                let reach = DVec2::splat(r + fine.max_radius);
                fine.cells.for_each_in_box(p - reach, p + reach, |k| {
                    let b = fine.members[fine.cells.order[k] as usize];
                    let (q, s) = circles[b as usize];
                    if space.offset(p, q).length_squared() < (r + s) * (r + s) {
                        pairs.push((a.min(b), a.max(b)));
                    }
                });
            }
        }
    }
    // A box wider than a periodic grid visits some cells twice; keep each pair once.
    sort_and_dedupe(pairs, start);
}

/// Sorts `pairs[start..]` and drops repeats.
fn sort_and_dedupe(pairs: &mut Vec<(u32, u32)>, start: usize) {
    let mut found = pairs.split_off(start);
    found.sort_unstable();
    found.dedup();
    pairs.append(&mut found);
}

/// The single-grid broad phase, for circles of similar size (see [`needs_levels`]): buckets
/// `circles` into `cells` (one largest diameter, `2 · max_radius`, wide), copies them into `sorted` in cell order
/// ([`CellList::order`]) and appends the overlapping pairs as positions in that order, each
/// pair's first member being the one with the lower input index.
///
/// Working in cell order keeps the scan, and whatever the caller does with the pairs, on
/// nearby memory instead of jumping through the circles in input order.
pub fn pairs_in_cell_order(
    cells: &mut CellList,
    space: Space,
    circles: &[Disc],
    max_radius: f64,
    sorted: &mut Vec<Disc>,
    pairs: &mut Vec<(u32, u32)>,
) {
    match space {
        Space::Open => cells.rebuild(circles, 2.0 * max_radius),
        Space::Periodic { min, size } => {
            cells.rebuild_periodic(circles, min, size, 2.0 * max_radius)
        }
    }
    let start = pairs.len();
    sorted.clear();
    sorted.resize(cells.order.len(), (DVec2::ZERO, 0.0));
    map_chunks(sorted, |from, out| {
        for (slot, &i) in out.iter_mut().zip(&cells.order[from..]) {
            *slot = circles[i as usize];
        }
    });
    if circles.len() >= PARALLEL_FROM {
        // Rows are independent: scan bands of rows on the task pool and append each band's
        // pairs in row order, so the result does not depend on the number of threads.
        let pool = ComputeTaskPool::get_or_init(TaskPool::default);
        let bands = (pool.thread_num() * 4).clamp(1, cells.rows);
        let per_band = cells.rows.div_ceil(bands);
        let cells = &*cells;
        let sorted = &*sorted;
        let found = pool.scope(|scope| {
            for band in 0..bands {
                let rows = band * per_band..((band + 1) * per_band).min(cells.rows);
                scope.spawn(async move {
                    let mut out = Vec::new();
                    scan_rows(cells, sorted, space, rows, &mut out);
                    out
                });
            }
        });
        for band in found {
            pairs.extend(band);
        }
    } else {
        scan_rows(cells, sorted, space, 0..cells.rows, pairs);
    }
    if cells.wraps_onto_itself() {
        sort_and_dedupe(pairs, start);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The broad phase's pairs, sorted, checked against brute force.
    fn pairs_checked(space: Space, positions: &[DVec2], radii: &[f64]) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        overlapping_pairs(
            &mut CellList::default(),
            space,
            positions,
            radii,
            &mut pairs,
        );
        pairs.sort_unstable();
        assert_eq!(
            pairs,
            brute_force(space, positions, radii),
            "{space:?}, n = {}",
            positions.len()
        );
        pairs
    }

    fn brute_force(space: Space, positions: &[DVec2], radii: &[f64]) -> Vec<(u32, u32)> {
        let mut pairs = Vec::new();
        for i in 0..positions.len() {
            for j in i + 1..positions.len() {
                let reach = radii[i] + radii[j];
                if space.offset(positions[i], positions[j]).length_squared() < reach * reach {
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
            let positions: Vec<DVec2> = (0..n)
                .map(|_| DVec2::new(rng.random_range(0.0..spread), rng.random_range(0.0..spread)))
                .collect();
            let radii: Vec<f64> = (0..n).map(|_| rng.random_range(0.01..0.3)).collect();
            pairs_checked(Space::Open, &positions, &radii);
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
            let space = Space::Periodic { min, size };
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
        for space in [
            Space::Open,
            Space::Periodic {
                min: DVec2::ZERO,
                size: DVec2::new(60.0, 40.0),
            },
        ] {
            let mut cells = CellList::default();
            let mut parallel = Vec::new();
            overlapping_pairs(&mut cells, space, &positions, &radii, &mut parallel);
            // One band over all rows: what a single thread does.
            let mut sequential = Vec::new();
            scan_rows(&cells, &cells.sorted, space, 0..cells.rows, &mut sequential);
            for pair in &mut sequential {
                *pair = (cells.order[pair.0 as usize], cells.order[pair.1 as usize]);
            }
            assert!(parallel.len() > 1000, "{}", parallel.len());
            assert_eq!(parallel, sequential);
        }
    }

    #[test]
    fn radii_spanning_decades_find_exactly_the_brute_force_pairs() {
        let mut rng = ChaCha8Rng::seed_from_u64(10);
        for periodic in [false, true] {
            let size = DVec2::new(1.0, 0.8);
            let space = if periodic {
                Space::Periodic {
                    min: DVec2::ZERO,
                    size,
                }
            } else {
                Space::Open
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
    fn non_finite_positions_take_part_in_no_pair() {
        let positions = [DVec2::ZERO, DVec2::new(f64::NAN, 0.0), DVec2::new(0.1, 0.0)];
        let mut pairs = Vec::new();
        overlapping_pairs(
            &mut CellList::default(),
            Space::Open,
            &positions,
            &[0.1; 3],
            &mut pairs,
        );
        assert_eq!(pairs, vec![(0, 2)]);
    }
}
