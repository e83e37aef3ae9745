//! The broad phase's cell list: circles binned into the cells of a `Grid` by one counting
//! sort per step (parallel for large N), so the circles of each cell sit side by side in
//! [`CellList::order`].

use bevy::math::DVec2;
use bevy::tasks::{ComputeTaskPool, ParallelSlice, ParallelSliceMut, TaskPool};

use crate::base::grid::Grid;

/// Circles bucketed by cell: `order[start[c]..start[c + 1]]` are the circles in cell `c`.
#[derive(Debug, Default, Clone)]
pub struct CellList {
    pub(super) grid: Grid,
    pub(super) start: Vec<u32>,
    pub(super) order: Vec<u32>,
    cell_of: Vec<u32>,
    /// Centres and reaches in `order`, reused by the translated single-grid scan.
    pub(super) sorted: Vec<(DVec2, f64)>,
}

/// No cell: the circle has a non-finite position and takes part in no pair.
const NO_CELL: u32 = u32::MAX;

/// Circle count from which the pair scan and the per-circle passes run on all cores.
pub const PARALLEL_FROM: usize = 4_000;

impl CellList {
    /// Buckets `circles` (centre, reach) into square cells at least `min_cell` wide. The grid
    /// covers the bounding box of the finite centres, and never has more than about four cells
    /// per circle (a tiny radius in a huge box gets wider cells, which stays correct and bounds
    /// memory).
    pub fn rebuild(&mut self, circles: &[(DVec2, f64)], min_cell: f64) {
        let n = circles.len();
        let (lo, hi) = fold_chunks(
            circles,
            |chunk| {
                let finite = chunk.iter().map(|c| c.0).filter(|p| p.is_finite());
                finite.fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), p| {
                    (lo.min(p), hi.max(p))
                })
            },
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
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
        let origin = if lo.x <= hi.x { lo } else { DVec2::ZERO };
        let inv_cell = 1.0 / cell;
        let cols = ((extent.x * inv_cell).floor() as usize + 1).max(1);
        let rows = ((extent.y * inv_cell).floor() as usize + 1).max(1);
        self.grid = Grid::square(origin, cell, cols, rows);
        self.fill(circles);
    }

    /// Buckets `circles` (centres already wrapped into the periodic box at `min` of this
    /// `size`) into a grid that tiles the box exactly, with cells at least `min_cell` wide.
    pub fn rebuild_periodic(
        &mut self,
        circles: &[(DVec2, f64)],
        min: DVec2,
        size: DVec2,
        min_cell: f64,
    ) {
        self.grid = Grid::tiling(min, size, min_cell, circles.len(), true);
        self.fill(circles);
    }

    /// Whether the periodic grid is too coarse for the wrapped half stencil to visit each
    /// neighbour cell once (fewer than three cells on an axis).
    pub fn wraps_onto_itself(&self) -> bool {
        self.grid.periodic && (self.grid.cols < 3 || self.grid.rows < 3)
    }

    /// The circles' input indices in cell order (circles with a non-finite centre left out).
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The grid the circles are binned into.
    pub(crate) fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The positions in [`Self::order`] of the circles in cell `c`.
    #[inline]
    pub(crate) fn cell_range(&self, c: usize) -> std::ops::Range<usize> {
        self.start[c] as usize..self.start[c + 1] as usize
    }

    fn fill(&mut self, circles: &[(DVec2, f64)]) {
        let cells = self.grid.len();
        let mut cell_of = std::mem::take(&mut self.cell_of);
        // Resized, not refilled: every element is written below (at a million circles,
        // writing them all first was a pass of its own).
        cell_of.resize(circles.len(), NO_CELL);
        let grid = self.grid;
        map_chunks(&mut cell_of, |from, out| {
            for (cell, c) in out.iter_mut().zip(&circles[from..]) {
                *cell = if c.0.is_finite() {
                    let (x, y) = grid.cell_of(c.0);
                    grid.index(x, y) as u32
                } else {
                    NO_CELL
                };
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
        // Resized, not refilled: each place is written once below.
        self.order.resize(placed, 0);
        // `start[c + 1]` is where cell `c` ends: filled from the back, each cell's circles end
        // up in input order and `start[c + 1]` where the cell begins, one place late (so no
        // cursor per cell, a table as large as `start`, is needed).
        for (i, &c) in self.cell_of.iter().enumerate().rev() {
            if c != NO_CELL {
                let slot = &mut self.start[c as usize + 1];
                *slot -= 1;
                self.order[*slot as usize] = i as u32;
            }
        }
        self.start.copy_within(1..=cells, 0);
        self.start[cells] = placed as u32;
    }

    /// Calls `visit(k)` for every circle (as its position `k` in the cell order) in the cells
    /// that the box `[lo, hi]` touches; on a periodic grid the box wraps around.
    pub fn for_each_in_box(&self, lo: DVec2, hi: DVec2, mut visit: impl FnMut(usize)) {
        let grid = &self.grid;
        let to_cell = |p: DVec2| ((p - grid.origin) / grid.cell).floor();
        let (a, b) = (to_cell(lo), to_cell(hi));
        let axis = |from: f64, to: f64, count: usize| -> Vec<usize> {
            if !(from.is_finite() && to.is_finite()) {
                return Vec::new();
            }
            if grid.periodic {
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
        let xs = axis(a.x, b.x, grid.cols);
        for y in axis(a.y, b.y, grid.rows) {
            for &x in &xs {
                let c = grid.index(x, y);
                (self.start[c] as usize..self.start[c + 1] as usize).for_each(&mut visit);
            }
        }
    }

    /// On a periodic grid, the circles (as ranges of positions in [`Self::order`]) that a
    /// circle of cell `(x, y)` is tested against: its own cell (the caller skips up to itself)
    /// and the "half stencil" (the cell to the right and the three above), wrapped around the
    /// seams. Ranges that meet are merged.
    pub(super) fn periodic_later_neighbours(
        &self,
        x: usize,
        y: usize,
    ) -> ([std::ops::Range<usize>; 5], usize) {
        let (cols, rows) = (self.grid.cols, self.grid.rows);
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

/// The smallest and largest reach (`(∞, 0)` for no circles), in one pass (on all cores for
/// many circles).
pub fn radius_range(circles: &[(DVec2, f64)]) -> (f64, f64) {
    fold_chunks(
        circles,
        |chunk| {
            chunk.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
                (lo.min(c.1), hi.max(c.1))
            })
        },
        |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
    )
}

/// Chunk length of [`map_chunks`] and [`fold_chunks`]: fixed, so that how a long input is
/// split does not depend on the threads.
const CHUNK: usize = 1 << 14;

/// `fold` over `items`: over chunks of it on all cores when it is longer than one chunk, the
/// chunks' values joined in order with `join` (the same chunks and order whatever the number of
/// threads).
fn fold_chunks<T: Sync, A: Send + 'static>(
    items: &[T],
    fold: impl Fn(&[T]) -> A + Send + Sync,
    join: impl Fn(A, A) -> A,
) -> A {
    // One chunk's fold is the whole fold.
    if items.len() <= CHUNK {
        return fold(items);
    }
    let pool = ComputeTaskPool::get_or_init(TaskPool::default);
    let chunks = items.par_chunk_map(pool, CHUNK, |_, chunk| fold(chunk));
    let mut chunks = chunks.into_iter();
    let first = chunks.next().expect("a long input has a first chunk");
    chunks.fold(first, join)
}

/// Fills `out` by calling `fill(offset, chunk)` on chunks of it, on all cores when it is long
/// (each element depends only on its index, so the result does not depend on the threads).
pub(super) fn map_chunks<T: Send>(mut out: &mut [T], fill: impl Fn(usize, &mut [T]) + Send + Sync) {
    if out.len() < PARALLEL_FROM {
        fill(0, out);
        return;
    }
    let pool = ComputeTaskPool::get_or_init(TaskPool::default);
    out.par_chunk_map_mut(pool, CHUNK, |index, chunk| fill(index * CHUNK, chunk));
}
