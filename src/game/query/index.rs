//! The index behind the spatial queries: the circles binned into cell lists by the broad
//! phase's counting sort ([`CellList`]), one list per size level when radii span more than
//! `MULTI_LEVEL_RATIO`, each cell's circles
//! stored side by side. A query near a point looks at the few cells around it; a ray walks
//! the cells it crosses in order (a grid traversal), testing the circles of the cells within
//! reach of each, and stops at the first cell past its nearest hit.
//!
//! # What it costs
//!
//! Per query, through [`SpatialQuery`](super::SpatialQuery) in a system as a game calls it, on
//! the benchmarks' gas (area fraction 0.3, radii 0.5-1): criterion medians of 1000 queries from
//! points spread over the arena, one run on a 2-core machine, 2026-12-02, `MC_BENCH_LARGE=1
//! cargo bench --bench queries -- --noplot --warm-up-time 1 --measurement-time 3`.
//!
//! | N | point | overlap, r = 1 | ray cast | circle cast, r = 0.5 | index build (first query after a step) |
//! |---:|---:|---:|---:|---:|---:|
//! | 10,000 | 0.13 µs | 0.33 µs | 0.72 µs | 0.67 µs | 0.42 ms |
//! | 1,000,000 | 0.30 µs | 0.38 µs | 0.93 µs | 0.77 µs | 56 ms |
//!
//! The build is the price at a million circles: a game that queries every step pays it every
//! step. Most of it runs on one core, and the broad phase's own cell list, built in the same
//! step, is not yet shared with it.

use bevy::math::DVec2;

use super::shapes::ray_disc;
use crate::base::arena::Arena;
use crate::base::grid::Grid;
use crate::collision::broad_phase::{CellList, needs_levels, radius_range};

/// How far a ray or a cast travels through the seams of a periodic arena at most: this many of
/// the box's diagonals (a ray on a torus can wind on without end).
pub const PERIODIC_REACH: f64 = 8.0;

/// Most size levels (a factor of 4 in radius each; larger circles share the last).
const MAX_LEVELS: usize = 64;

/// The circles, as centres and radii by their index in the slice they were built from.
#[derive(Debug, Default, Clone)]
pub struct CircleIndex {
    levels: Vec<Level>,
    /// The arena it was built for.
    arena: Arena,
    /// Circles of one level while building, reused.
    local: Vec<(DVec2, f64)>,
}

#[derive(Debug, Default, Clone)]
struct Level {
    cells: CellList,
    /// `(centre, radius, index)` of the level's circles in cell order.
    sorted: Vec<(DVec2, f64, u32)>,
    max_radius: f64,
}

/// The nearest circle a cast meets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CircleHitAt {
    /// Its index.
    pub index: u32,
    /// How far the cast travelled to meet it.
    pub distance: f64,
    /// Its centre, as the image the cast meets on a periodic arena.
    pub centre: DVec2,
    /// Its radius.
    pub radius: f64,
}

impl CircleIndex {
    /// Rebuilds the index over `circles` (centre, radius) in `arena`, reusing its memory.
    /// Circles with a non-finite centre are left out.
    pub fn build(&mut self, circles: &[(DVec2, f64)], arena: &Arena) {
        self.arena = *arena;
        let range = radius_range(circles);
        let level_of = |r: f64| {
            if needs_levels(range) {
                ((r / range.0).log2() / 2.0)
                    .floor()
                    .clamp(0.0, (MAX_LEVELS - 1) as f64) as usize
            } else {
                0
            }
        };
        let count = circles.iter().map(|c| level_of(c.1) + 1).max().unwrap_or(0);
        self.levels.resize_with(count, Level::default);
        for (k, level) in self.levels.iter_mut().enumerate() {
            let members = circles
                .iter()
                .enumerate()
                .filter(|(_, c)| level_of(c.1) == k);
            self.local.clear();
            level.sorted.clear();
            for (i, &(centre, radius)) in members {
                let periodic = arena.is_periodic() && centre.is_finite();
                let centre = if periodic { arena.wrap(centre) } else { centre };
                self.local.push((centre, radius));
                level.sorted.push((centre, radius, i as u32));
            }
            level.max_radius = radius_range(&self.local).1;
            let min_cell = 2.0 * level.max_radius;
            if arena.is_periodic() {
                let (min, size) = (arena.min, arena.size());
                level
                    .cells
                    .rebuild_periodic(&self.local, min, size, min_cell);
            } else {
                level.cells.rebuild(&self.local, min_cell);
            }
            let unsorted = std::mem::take(&mut level.sorted);
            level
                .sorted
                .extend(level.cells.order().iter().map(|&j| unsorted[j as usize]));
        }
    }

    /// Calls `visit(index, offset, radius)` for every circle whose centre lies within
    /// `reach` plus its own radius of `p` on each axis (a superset of those within that
    /// distance), with `offset` from `p` to its centre (the minimum image on a periodic
    /// arena). Each circle comes at most once.
    pub fn for_each_near(&self, p: DVec2, reach: f64, mut visit: impl FnMut(u32, DVec2, f64)) {
        let arena = &self.arena;
        let p = if arena.is_periodic() {
            arena.wrap(p)
        } else {
            p
        };
        if !p.is_finite() {
            return;
        }
        for level in &self.levels {
            let half = DVec2::splat(reach + level.max_radius);
            let grid = level.cells.grid();
            let (lo, hi) = (grid_coords(grid, p - half), grid_coords(grid, p + half));
            let (Some(xs), Some(ys)) = (
                axis_span(lo.x, hi.x, grid.cols, grid.periodic),
                axis_span(lo.y, hi.y, grid.rows, grid.periodic),
            ) else {
                continue;
            };
            for y in ys.0..ys.0 + ys.1 as i64 {
                for x in xs.0..xs.0 + xs.1 as i64 {
                    let c = grid.index(wrap(x, grid.cols), wrap(y, grid.rows));
                    for &(centre, radius, i) in &level.sorted[level.cells.cell_range(c)] {
                        visit(i, arena.offset(p, centre), radius);
                    }
                }
            }
        }
    }

    /// The first circle, among those `accept` takes, that a circle of `radius` (0 for a ray)
    /// moving from `origin` along the unit `direction` meets within `max_distance`: the one
    /// met at the shortest distance, the lowest index on a tie. A circle already overlapping
    /// at the start is met at distance 0. On a periodic arena the cast wraps through the seams
    /// for at most [`PERIODIC_REACH`] diagonals of the box, exact while `radius` plus the
    /// largest circle's is below half the box's shorter side (a wider cast may miss images of a
    /// circle beyond the nearest).
    pub fn cast(
        &self,
        origin: DVec2,
        direction: DVec2,
        radius: f64,
        max_distance: f64,
        accept: impl Fn(u32) -> bool,
    ) -> Option<CircleHitAt> {
        if !(origin.is_finite() && direction.is_finite() && radius >= 0.0 && max_distance >= 0.0) {
            return None;
        }
        let arena = &self.arena;
        let (start, shift, max_distance) = if arena.is_periodic() {
            let wrapped = arena.wrap(origin);
            let reach = PERIODIC_REACH * arena.size().length();
            (wrapped, origin - wrapped, max_distance.min(reach))
        } else {
            (origin, DVec2::ZERO, max_distance)
        };
        let ray = Ray {
            origin: start,
            direction,
            radius,
            max_distance,
        };
        let mut best: Option<CircleHitAt> = None;
        for level in &self.levels {
            ray.walk(
                level,
                arena.is_periodic().then(|| arena.size()),
                &accept,
                &mut best,
            );
        }
        best.map(|hit| CircleHitAt {
            centre: hit.centre + shift,
            ..hit
        })
    }
}

/// One cast through one level's cells.
struct Ray {
    origin: DVec2,
    direction: DVec2,
    radius: f64,
    max_distance: f64,
}

impl Ray {
    /// Walks the cells the ray crosses, from the first it reaches, testing every circle of the
    /// cells within its reach of each (each new ring of cells once), until past `best` or
    /// `max_distance`.
    fn walk(
        &self,
        level: &Level,
        period: Option<DVec2>,
        accept: &impl Fn(u32) -> bool,
        best: &mut Option<CircleHitAt>,
    ) {
        let grid = level.cells.grid();
        let reach = level.max_radius + self.radius;
        // Rings of cells around the ray's cell that hold every centre within `reach` of it
        // (one more than needed, against rounding at the cell edges).
        // On a periodic grid, rings past a whole period would only add images farther than
        // half the box (see `CircleIndex::cast`).
        let rings = |cell: f64, count: usize| {
            let k = (reach / cell).floor() + 1.0;
            if grid.periodic {
                k.min(count as f64)
            } else {
                k.min(1e9)
            }
        };
        let (kx, ky) = (rings(grid.cell.x, grid.cols), rings(grid.cell.y, grid.rows));
        if !grid.periodic && (2.0 * kx + 1.0) * (2.0 * ky + 1.0) >= grid.len() as f64 {
            // The cast is as wide as the grid: every circle of it is within reach anyway.
            for c in 0..grid.len() {
                self.test_cell(
                    level,
                    grid,
                    None,
                    (c % grid.cols) as i64,
                    (c / grid.cols) as i64,
                    accept,
                    best,
                );
            }
            return;
        }
        let (kx, ky) = (kx as i64, ky as i64);
        let (o, d) = (self.origin, self.direction);
        // Where the ray is within reach of the grid: all of it on a periodic one, else the
        // stretch inside the grid grown by the rings.
        let (t_start, t_end) = if grid.periodic {
            (0.0, self.max_distance)
        } else {
            let grown = DVec2::new(kx as f64, ky as f64) * grid.cell;
            let lo = grid.origin - grown;
            let hi =
                grid.origin + DVec2::new(grid.cols as f64, grid.rows as f64) * grid.cell + grown;
            let Some((t0, t1)) = slab(o, d, lo, hi) else {
                return;
            };
            (t0.max(0.0), t1.min(self.max_distance))
        };
        if t_start > t_end {
            return;
        }
        let at = grid_coords(grid, o + d * t_start).floor();
        let clamp = |c: f64, k: i64, count: usize| {
            if grid.periodic {
                c as i64
            } else {
                (c as i64).clamp(-k, count as i64 - 1 + k)
            }
        };
        let (mut ix, mut iy) = (clamp(at.x, kx, grid.cols), clamp(at.y, ky, grid.rows));
        let step = DVec2::new(d.x.signum(), d.y.signum());
        let boundary = |i: i64, axis: usize| {
            let next = i + i64::from(step[axis] > 0.0);
            let edge = grid.origin[axis] + next as f64 * grid.cell[axis];
            if d[axis] == 0.0 {
                f64::INFINITY
            } else {
                (edge - o[axis]) / d[axis]
            }
        };
        let (mut t_x, mut t_y) = (boundary(ix, 0), boundary(iy, 1));
        let delta = grid.cell / d.abs();
        let test = |bx: i64, by: i64, best: &mut Option<CircleHitAt>| {
            self.test_cell(level, grid, period, bx, by, accept, best);
        };
        for by in iy - ky..=iy + ky {
            for bx in ix - kx..=ix + kx {
                test(bx, by, best);
            }
        }
        // Each step enters one cell, so the walk ends within the cells the stretch crosses.
        let span = (t_end - t_start) / grid.cell;
        let most_steps = (span.x + span.y).min(1e12) as u64 + 4 * (grid.cols + grid.rows) as u64;
        for _ in 0..most_steps {
            let t_exit = t_x.min(t_y);
            if best.is_some_and(|b| b.distance < t_exit) || t_exit >= t_end {
                return;
            }
            if t_x < t_y {
                ix += step.x as i64;
                t_x += delta.x;
                let bx = ix + step.x as i64 * kx;
                (iy - ky..=iy + ky).for_each(|by| test(bx, by, best));
            } else {
                iy += step.y as i64;
                t_y += delta.y;
                let by = iy + step.y as i64 * ky;
                (ix - kx..=ix + kx).for_each(|bx| test(bx, by, best));
            }
        }
    }

    /// Tests the circles of cell `(bx, by)` (unwrapped: on a periodic grid, the image of a
    /// cell a whole number of periods away).
    #[allow(clippy::too_many_arguments)]
    fn test_cell(
        &self,
        level: &Level,
        grid: &Grid,
        period: Option<DVec2>,
        bx: i64,
        by: i64,
        accept: &impl Fn(u32) -> bool,
        best: &mut Option<CircleHitAt>,
    ) {
        let (cols, rows) = (grid.cols as i64, grid.rows as i64);
        let image = match period {
            Some(size) => DVec2::new(
                bx.div_euclid(cols) as f64 * size.x,
                by.div_euclid(rows) as f64 * size.y,
            ),
            None if bx < 0 || by < 0 || bx >= cols || by >= rows => return,
            None => DVec2::ZERO,
        };
        let c = grid.index(wrap(bx, grid.cols), wrap(by, grid.rows));
        for &(centre, radius, index) in &level.sorted[level.cells.cell_range(c)] {
            if !accept(index) {
                continue;
            }
            let centre = centre + image;
            let Some(t) = ray_disc(self.origin, self.direction, centre, radius + self.radius)
            else {
                continue;
            };
            let better = best.is_none_or(|b| (t, index) < (b.distance, b.index));
            if t <= self.max_distance && better {
                *best = Some(CircleHitAt {
                    index,
                    distance: t,
                    centre,
                    radius,
                });
            }
        }
    }
}

/// `p` in cell units of `grid` (not floored).
fn grid_coords(grid: &Grid, p: DVec2) -> DVec2 {
    (p - grid.origin) / grid.cell
}

/// The cells `floor(from)..=floor(to)` of an axis of `count` cells, as a first cell and a
/// length: all of them once on a periodic axis the span covers, clipped to the axis on a
/// plain one (`None` if it misses).
fn axis_span(from: f64, to: f64, count: usize, periodic: bool) -> Option<(i64, usize)> {
    let (from, to) = (from.floor(), to.floor());
    if from.is_nan() || to.is_nan() || to < from {
        return None;
    }
    if periodic {
        if to - from + 1.0 >= count as f64 {
            return Some((0, count));
        }
        return Some((from as i64, (to - from) as usize + 1));
    }
    let last = (count - 1) as f64;
    if to < 0.0 || from > last {
        return None;
    }
    let (a, b) = (from.max(0.0), to.min(last));
    Some((a as i64, (b - a) as usize + 1))
}

/// Cell `i` of an axis of `count` cells, wrapped (a plain axis's callers pass cells inside).
#[inline]
fn wrap(i: i64, count: usize) -> usize {
    i.rem_euclid(count as i64) as usize
}

/// The stretch `(t0, t1)` of the ray `o + t·d` inside the box `[lo, hi]`, if it meets it.
fn slab(o: DVec2, d: DVec2, lo: DVec2, hi: DVec2) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for axis in 0..2 {
        if d[axis] == 0.0 {
            if o[axis] < lo[axis] || o[axis] > hi[axis] {
                return None;
            }
            continue;
        }
        let (a, b) = (
            (lo[axis] - o[axis]) / d[axis],
            (hi[axis] - o[axis]) / d[axis],
        );
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t0 <= t1).then_some((t0, t1))
}
