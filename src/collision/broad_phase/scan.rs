//! The single-grid pair scan: per circle in cell order, the rest of its own cell and the "half
//! stencil" (the cell to the right and the three above), so each pair is visited once. Large
//! scans split the rows into bands on the task pool and join the bands in row order, so the
//! pairs and their order never depend on the number of threads.

use std::ops::ControlFlow;

use bevy::math::DVec2;
use bevy::tasks::{ComputeTaskPool, TaskPool};

use super::cells::{CellList, PARALLEL_FROM, map_chunks};
use crate::base::arena::{Arena, minimum_image};

/// The single-grid broad phase, for circles of similar size: buckets `circles` (centre, reach)
/// into `cells` (one largest diameter, `2 · max_radius`, wide), copies them into `sorted` in
/// cell order ([`CellList::order`]) and appends the overlapping pairs as positions in that
/// order, each pair's first member being the one with the lower input index.
///
/// Working in cell order keeps the scan, and whatever the caller does with the pairs, on
/// nearby memory instead of jumping through the circles in input order.
pub fn pairs_in_cell_order(
    cells: &mut CellList,
    arena: &Arena,
    circles: &[(DVec2, f64)],
    max_radius: f64,
    sorted: &mut Vec<(DVec2, f64)>,
    pairs: &mut Vec<(u32, u32)>,
) {
    bin_in_cell_order(cells, arena, circles, max_radius, sorted);
    let start = pairs.len();
    let rows = cells.grid.rows;
    if circles.len() >= PARALLEL_FROM {
        let pool = ComputeTaskPool::get_or_init(TaskPool::default);
        let bands = (pool.thread_num() * 4).clamp(1, rows);
        let per_band = rows.div_ceil(bands);
        let cells = &*cells;
        let sorted = &*sorted;
        let found = pool.scope(|scope| {
            for band in 0..bands {
                let rows = band * per_band..((band + 1) * per_band).min(rows);
                scope.spawn(async move {
                    let mut out = Vec::new();
                    scan_rows(cells, sorted, arena, rows, &mut out);
                    out
                });
            }
        });
        for band in found {
            pairs.extend(band);
        }
    } else {
        scan_rows(cells, sorted, arena, 0..rows, pairs);
    }
    if cells.wraps_onto_itself() {
        sort_and_dedupe(pairs, start);
    }
}

/// Buckets `circles` into `cells` (one largest diameter wide) and copies them into `sorted` in
/// cell order.
fn bin_in_cell_order(
    cells: &mut CellList,
    arena: &Arena,
    circles: &[(DVec2, f64)],
    max_radius: f64,
    sorted: &mut Vec<(DVec2, f64)>,
) {
    if arena.is_periodic() {
        cells.rebuild_periodic(circles, arena.min, arena.size(), 2.0 * max_radius);
    } else {
        cells.rebuild(circles, 2.0 * max_radius);
    }
    // Resized, not refilled: every place is written below.
    sorted.resize(cells.order.len(), (DVec2::ZERO, 0.0));
    map_chunks(sorted, |from, out| {
        for (slot, &i) in out.iter_mut().zip(&cells.order[from..]) {
            *slot = circles[i as usize];
        }
    });
}

/// Rows of cells per band of [`fold_pairs_by_band`], at least: a number fixed by the grid, so
/// that which pairs are folded together, and in what order, does not depend on the threads.
const BAND_ROWS: usize = 16;
/// Bands of [`fold_pairs_by_band`], at most (a grid one cell wide may have 4 N rows).
const MAX_BANDS: usize = 1024;

/// Folds every overlapping pair of `circles` (centre, reach), as input indices `(i, j)` with
/// `i < j` and the two circles (read in cell order, near each other in memory), into one value
/// per band of rows of the single-level grid (pairs in scan order within a band),
/// the bands on all cores for large inputs, without listing the pairs; returns the bands'
/// values in row order, the same whatever the number of threads.
/// `None` where the grid is too coarse for each pair to come once (a periodic arena a few
/// cells wide): the caller lists the pairs instead.
pub fn fold_pairs_by_band<T: Send + 'static>(
    arena: &Arena,
    circles: &[(DVec2, f64)],
    max_radius: f64,
    empty: impl Fn() -> T + Sync,
    fold: impl Fn(&mut T, (usize, usize), ((DVec2, f64), (DVec2, f64))) + Sync,
) -> Option<Vec<T>> {
    let (mut cells, mut sorted) = (CellList::default(), Vec::new());
    bin_in_cell_order(&mut cells, arena, circles, max_radius, &mut sorted);
    if cells.wraps_onto_itself() {
        return None;
    }
    let (cells, sorted) = (&cells, &sorted);
    let band = |rows: std::ops::Range<usize>| {
        let mut value = empty();
        let _ = visit_rows(cells, sorted, arena, rows, &mut |k, l| {
            let (k, l) = (k as usize, l as usize);
            let (i, j) = (cells.order[k] as usize, cells.order[l] as usize);
            fold(&mut value, (i, j), (sorted[k], sorted[l]));
            ControlFlow::Continue(())
        });
        value
    };
    let rows = cells.grid.rows;
    let per_band = BAND_ROWS.max(rows.div_ceil(MAX_BANDS));
    let bands = (0..rows.div_ceil(per_band)).map(|b| b * per_band..((b + 1) * per_band).min(rows));
    if circles.len() < PARALLEL_FROM {
        return Some(bands.map(band).collect());
    }
    let pool = ComputeTaskPool::get_or_init(TaskPool::default);
    let band = &band;
    Some(pool.scope(|scope| {
        for rows in bands {
            scope.spawn(async move { band(rows) });
        }
    }))
}

/// [`pairs_in_cell_order`] with the pairs translated back to input indices.
pub fn single_level_pairs(
    cells: &mut CellList,
    arena: &Arena,
    circles: &[(DVec2, f64)],
    max_radius: f64,
    pairs: &mut Vec<(u32, u32)>,
) {
    let start = pairs.len();
    let mut sorted = std::mem::take(&mut cells.sorted);
    pairs_in_cell_order(cells, arena, circles, max_radius, &mut sorted, pairs);
    cells.sorted = sorted;
    for pair in &mut pairs[start..] {
        *pair = (cells.order[pair.0 as usize], cells.order[pair.1 as usize]);
    }
}

/// Sorts `pairs[start..]` and drops repeats.
pub fn sort_and_dedupe(pairs: &mut Vec<(u32, u32)>, start: usize) {
    let mut found = pairs.split_off(start);
    found.sort_unstable();
    found.dedup();
    pairs.append(&mut found);
}

/// Scans the cells of `rows`, appending overlapping pairs. Visiting circles rather than cells
/// skips the empty cells, which outnumber circles in a sparse gas.
pub(super) fn scan_rows(
    cells: &CellList,
    sorted: &[(DVec2, f64)],
    arena: &Arena,
    rows: std::ops::Range<usize>,
    pairs: &mut Vec<(u32, u32)>,
) {
    let _ = visit_rows(cells, sorted, arena, rows, &mut |k, l| {
        pairs.push((k, l));
        ControlFlow::Continue(())
    });
}

/// Hands each overlapping pair of `rows` (positions in cell order, oriented as in
/// [`pairs_in_cell_order`]) to `visit` until it says stop.
pub(super) fn visit_rows(
    cells: &CellList,
    sorted: &[(DVec2, f64)],
    arena: &Arena,
    rows: std::ops::Range<usize>,
    visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> ControlFlow<()> {
    if arena.is_periodic() {
        let size = arena.size();
        visit_rows_with(
            cells,
            sorted,
            |a, b| minimum_image(b - a, size),
            rows,
            visit,
        )
    } else {
        visit_rows_with(cells, sorted, |a, b| b - a, rows, visit)
    }
}

/// The serial single-grid scan of every pair of `circles` (centre, reach) that overlaps, as
/// input indices `(i, j)` with `i < j`, handed to `visit` until it says stop. Needs no memory
/// beyond the cell list, however many pairs overlap (a periodic grid narrower than three cells
/// may show a pair twice).
pub fn visit_single_level(
    cells: &mut CellList,
    arena: &Arena,
    circles: &[(DVec2, f64)],
    max_radius: f64,
    visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> ControlFlow<()> {
    if arena.is_periodic() {
        cells.rebuild_periodic(circles, arena.min, arena.size(), 2.0 * max_radius);
    } else {
        cells.rebuild(circles, 2.0 * max_radius);
    }
    let sorted: Vec<(DVec2, f64)> = cells.order.iter().map(|&i| circles[i as usize]).collect();
    let order = &cells.order;
    visit_rows(cells, &sorted, arena, 0..cells.grid.rows, &mut |k, l| {
        visit(order[k as usize], order[l as usize])
    })
}

/// [`visit_rows`] with the displacement function fixed at compile time.
fn visit_rows_with(
    cells: &CellList,
    sorted: &[(DVec2, f64)],
    offset: impl Fn(DVec2, DVec2) -> DVec2,
    rows: std::ops::Range<usize>,
    visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> ControlFlow<()> {
    let (cols, start) = (cells.grid.cols, &cells.start);
    for y in rows {
        let row = y * cols;
        for x in 0..cols {
            let here = start[row + x] as usize..start[row + x + 1] as usize;
            if here.is_empty() {
                continue;
            }
            let (ranges, len) = if cells.grid.periodic {
                cells.periodic_later_neighbours(x, y)
            } else {
                // Open grid, written out: own and right cell, then the three cells above.
                let right = (x + 1).min(cols - 1);
                let mut ranges: [std::ops::Range<usize>; 5] = Default::default();
                ranges[0] = here.start..start[row + right + 1] as usize;
                if y + 1 < cells.grid.rows {
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
                            let (a, b) = if lower_first { (k, l) } else { (l, k) };
                            visit(a, b)?;
                        }
                    }
                }
            }
        }
    }
    ControlFlow::Continue(())
}
