//! Uniform grids of cells: [`Grid`], the geometry shared by everything that buckets circles by
//! position (spawn placement, the discrete broad phase, the event engine), and [`CellMembers`],
//! per-cell lists that circles join and leave one at a time (placement and the event engine; the
//! broad phase rebuilds its cells in one counting sort instead).

use bevy::math::DVec2;

/// A grid of `cols × rows` cells from `origin`, on a plain or a periodic rectangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Corner of cell `(0, 0)`.
    pub origin: DVec2,
    /// Width and height of a cell.
    pub cell: DVec2,
    /// Cells along x.
    pub cols: usize,
    /// Cells along y.
    pub rows: usize,
    /// Whether neighbours wrap around the edges.
    pub periodic: bool,
}

impl Default for Grid {
    fn default() -> Self {
        Self::square(DVec2::ZERO, 1.0, 1, 1)
    }
}

/// No circle: the end of a cell's member list.
pub const NONE: u32 = u32::MAX;

impl Grid {
    /// Square cells `cell` wide, `cols × rows` of them from `origin`; no wrapping.
    pub fn square(origin: DVec2, cell: f64, cols: usize, rows: usize) -> Self {
        Self {
            origin,
            cell: DVec2::splat(cell),
            cols,
            rows,
            periodic: false,
        }
    }

    /// Cells that tile the rectangle at `origin` of this `size` exactly, as close to `min_cell`
    /// wide as fits, and never more than about four per circle on the whole (so a tiny circle in
    /// a huge box cannot allocate millions of empty cells; wider cells stay correct). A periodic
    /// grid keeps at least four cells a side where they fit, however few the circles: with
    /// three, a cell's neighbour on one side is its neighbour on the other too, so a pair can
    /// come to meet through another image without either circle crossing into a new cell.
    pub fn tiling(
        origin: DVec2,
        size: DVec2,
        min_cell: f64,
        circles: usize,
        periodic: bool,
    ) -> Self {
        let cap = ((4 * circles).max(1) as f64).sqrt().ceil();
        let cap = if periodic { cap.max(4.0) } else { cap };
        let count = |length: f64| {
            let fit = (length / min_cell.max(f64::MIN_POSITIVE)).floor();
            (fit.min(cap) as usize).max(1)
        };
        let (cols, rows) = (count(size.x), count(size.y));
        Self {
            origin,
            cell: DVec2::new(size.x / cols as f64, size.y / rows as f64),
            cols,
            rows,
            periodic,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cols * self.rows
    }

    /// Whether the grid has no cells (never: every constructor makes at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cell holding `p`, clamped onto the grid (so a point on or past an edge by rounding
    /// belongs to the edge cell). `p` must be finite.
    ///
    /// It divides by the cell size rather than multiplying by its inverse: a point exactly on a
    /// cell boundary (a lattice of touching circles has many) then lands in the same cell every
    /// time, whichever part of the code asks.
    #[inline]
    pub fn cell_of(&self, p: DVec2) -> (usize, usize) {
        let c = (p - self.origin) / self.cell;
        (
            (c.x.max(0.0) as usize).min(self.cols - 1),
            (c.y.max(0.0) as usize).min(self.rows - 1),
        )
    }

    /// Index of cell `(x, y)`.
    #[inline]
    pub fn index(&self, x: usize, y: usize) -> usize {
        y * self.cols + x
    }

    /// Cell `(x + dx, y + dy)`: wrapped on a periodic grid, `None` past the edge of a plain one.
    #[inline]
    pub fn neighbour(&self, x: usize, y: usize, dx: i64, dy: i64) -> Option<usize> {
        let (cols, rows) = (self.cols as i64, self.rows as i64);
        let (mut x, mut y) = (x as i64 + dx, y as i64 + dy);
        if self.periodic {
            // Most neighbours are inside the grid: no division for them.
            let wrap = |v: i64, n: i64| {
                if (0..n).contains(&v) {
                    v
                } else {
                    v.rem_euclid(n)
                }
            };
            (x, y) = (wrap(x, cols), wrap(y, rows));
        } else if x < 0 || y < 0 || x >= cols || y >= rows {
            return None;
        }
        Some((y * cols + x) as usize)
    }

    /// The distinct cells of the 3×3 block around `(x, y)`, row by row: fewer at a plain
    /// grid's edge, and each once where a tiny periodic grid wraps onto itself.
    #[inline]
    pub fn block(&self, x: usize, y: usize) -> ([usize; 9], usize) {
        let mut cells = [0usize; 9];
        let mut len = 0;
        if !self.periodic {
            // Spawning asks this for every placement attempt: clip, and nothing to deduplicate.
            for cy in y.saturating_sub(1)..=(y + 1).min(self.rows - 1) {
                for cx in x.saturating_sub(1)..=(x + 1).min(self.cols - 1) {
                    cells[len] = cy * self.cols + cx;
                    len += 1;
                }
            }
            return (cells, len);
        }
        for dy in -1..=1 {
            for dx in -1..=1 {
                if let Some(c) = self.neighbour(x, y, dx, dy)
                    && !cells[..len].contains(&c)
                {
                    cells[len] = c;
                    len += 1;
                }
            }
        }
        (cells, len)
    }

    /// [`Grid::block`] where the block lies inside the grid, nothing clipped or wrapped: its nine
    /// cells as plain indices in the same order, for the event engine's hottest loop. `None`
    /// near the edges.
    #[inline]
    pub fn inner_block(&self, x: usize, y: usize) -> Option<[usize; 9]> {
        if !self.is_inner(x, y) {
            return None;
        }
        let c = self.index(x, y);
        let (below, above) = (c - self.cols, c + self.cols);
        Some([
            below - 1,
            below,
            below + 1,
            c - 1,
            c,
            c + 1,
            above - 1,
            above,
            above + 1,
        ])
    }

    /// The three cells beside `(x, y)` on its side `up` (or down) along `axis`, from −1 to +1
    /// along the other axis: what a circle newly borders after crossing into `(x, y)`. Wrapped
    /// on a periodic grid, fewer past the edge of a plain one.
    #[inline]
    pub fn ahead(
        &self,
        x: usize,
        y: usize,
        axis: usize,
        up: bool,
    ) -> impl Iterator<Item = usize> + '_ {
        let ahead = if up { 1 } else { -1 };
        (-1..=1).filter_map(move |side| {
            let (dx, dy) = if axis == 0 {
                (ahead, side)
            } else {
                (side, ahead)
            };
            self.neighbour(x, y, dx, dy)
        })
    }

    /// [`Grid::ahead`] where those cells lie inside the grid: as plain indices in the same
    /// order. `None` near the edges.
    #[inline]
    pub fn inner_ahead(&self, x: usize, y: usize, axis: usize, up: bool) -> Option<[usize; 3]> {
        if !self.is_inner(x, y) {
            return None;
        }
        let (step, side) = if axis == 0 {
            (1, self.cols)
        } else {
            (self.cols, 1)
        };
        let c = self.index(x, y);
        let middle = if up { c + step } else { c - step };
        Some([middle - side, middle, middle + side])
    }

    /// Whether `(x, y)` has a cell on every side within the grid.
    #[inline]
    fn is_inner(&self, x: usize, y: usize) -> bool {
        (1..self.cols - 1).contains(&x) && (1..self.rows - 1).contains(&y)
    }

    /// The coordinate of the `k`-th cell boundary along `axis`.
    #[inline]
    pub fn edge(&self, axis: usize, k: usize) -> f64 {
        self.origin[axis] + self.cell[axis] * k as f64
    }
}

/// Which circles are in which cell (of the arena, or of time in the event queue), as one linked
/// list per cell: a circle joins or leaves a cell in O(1), and a cell's members are listed
/// newest first.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CellMembers {
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
}

impl CellMembers {
    /// `cells` empty cells for circles `0..circles`.
    pub fn new(cells: usize, circles: usize) -> Self {
        Self {
            head: vec![NONE; cells],
            next: vec![NONE; circles],
            prev: vec![NONE; circles],
        }
    }

    /// Empties every cell.
    pub fn clear(&mut self) {
        self.head.fill(NONE);
    }

    /// Puts circle `i` (not in any cell) into `cell`.
    #[inline]
    pub fn insert(&mut self, i: usize, cell: usize) {
        let first = self.head[cell];
        self.next[i] = first;
        self.prev[i] = NONE;
        if first != NONE {
            self.prev[first as usize] = i as u32;
        }
        self.head[cell] = i as u32;
    }

    /// Takes circle `i` out of `cell`, which holds it.
    #[inline]
    pub fn remove(&mut self, i: usize, cell: usize) {
        let (p, n) = (self.prev[i], self.next[i]);
        if p != NONE {
            self.next[p as usize] = n;
        } else {
            self.head[cell] = n;
        }
        if n != NONE {
            self.prev[n as usize] = p;
        }
    }

    /// Whether these lists hold each of `circles` circles exactly once, in `cells` cells, circle
    /// `i` in cell `cell_of(i)` (in none where that is `None`), with every link consistent: what
    /// lists read from outside (a checkpoint) must show before anything walks them. Says what is
    /// wrong.
    pub fn check(
        &self,
        cells: usize,
        circles: usize,
        cell_of: impl Fn(usize) -> Option<usize>,
    ) -> Result<(), String> {
        if self.head.len() != cells || self.next.len() != circles || self.prev.len() != circles {
            return Err(format!(
                "cell lists for {} cells and {} circles, expected {cells} and {circles}",
                self.head.len(),
                self.next.len()
            ));
        }
        let mut seen = vec![false; circles];
        for (cell, &head) in self.head.iter().enumerate() {
            let (mut at, mut before) = (head, NONE);
            while at != NONE {
                let i = at as usize;
                if i >= circles || seen[i] || self.prev[i] != before || cell_of(i) != Some(cell) {
                    return Err(format!("cell {cell}'s list is broken at circle {at}"));
                }
                seen[i] = true;
                (before, at) = (at, self.next[i]);
            }
        }
        match (0..circles).find(|&i| !seen[i] && cell_of(i).is_some()) {
            Some(i) => Err(format!("circle {i} is in no cell list")),
            None => Ok(()),
        }
    }

    /// The circles in `cell`, newest first.
    #[inline]
    pub fn members(&self, cell: usize) -> Members<'_> {
        Members {
            next: &self.next,
            at: self.head[cell],
        }
    }
}

/// Iterator over one cell's circles ([`CellMembers::members`]).
#[derive(Clone, Debug)]
pub struct Members<'a> {
    next: &'a [u32],
    at: u32,
}

impl Iterator for Members<'_> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        if self.at == NONE {
            return None;
        }
        let i = self.at as usize;
        self.at = self.next[i];
        Some(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_find_their_cell_and_edges_clamp() {
        let grid = Grid::square(DVec2::new(-1.0, 0.0), 0.5, 4, 2);
        assert_eq!(grid.cell_of(DVec2::new(-0.9, 0.1)), (0, 0));
        assert_eq!(grid.cell_of(DVec2::new(0.6, 0.9)), (3, 1));
        assert_eq!(grid.cell_of(DVec2::new(-5.0, 7.0)), (0, 1), "clamped");
        assert_eq!(grid.edge(0, 2), 0.0);
    }

    #[test]
    fn blocks_clip_at_plain_edges_and_wrap_once_on_tiny_periodic_grids() {
        let plain = Grid::square(DVec2::ZERO, 1.0, 3, 3);
        assert_eq!(plain.block(0, 0).1, 4);
        assert_eq!(plain.block(1, 1).1, 9);
        let tiny = Grid::tiling(DVec2::ZERO, DVec2::new(2.0, 1.0), 1.0, 10, true);
        assert_eq!((tiny.cols, tiny.rows), (2, 1));
        let (cells, len) = tiny.block(0, 0);
        assert_eq!(&cells[..len], &[1, 0], "each cell once");
        assert_eq!(tiny.neighbour(0, 0, -1, 0), Some(1));
        assert_eq!(plain.neighbour(0, 0, -1, 0), None);
    }

    #[test]
    fn inner_cells_are_the_plain_ones_in_the_same_order() {
        // The event engine keeps the first of equally soon partners: the plain arrays must list
        // the cells exactly as the general paths do, and be there for every inner cell.
        for periodic in [false, true] {
            for (cols, rows) in [(1, 1), (2, 3), (3, 3), (4, 6), (7, 5)] {
                let mut grid = Grid::square(DVec2::ZERO, 1.0, cols, rows);
                grid.periodic = periodic;
                let (mut blocks, mut aheads) = (0, 0);
                for (x, y) in (0..cols).flat_map(|x| (0..rows).map(move |y| (x, y))) {
                    if let Some(inner) = grid.inner_block(x, y) {
                        let (cells, len) = grid.block(x, y);
                        assert_eq!(inner[..], cells[..len], "({x}, {y}) of {cols}×{rows}");
                        blocks += 1;
                    }
                    for (axis, up) in [(0, false), (0, true), (1, false), (1, true)] {
                        if let Some(inner) = grid.inner_ahead(x, y, axis, up) {
                            let cells: Vec<usize> = grid.ahead(x, y, axis, up).collect();
                            assert_eq!(
                                inner[..],
                                cells,
                                "({x}, {y}) of {cols}×{rows}, {axis} {up}"
                            );
                            aheads += 1;
                        }
                    }
                }
                let inner = cols.saturating_sub(2) * rows.saturating_sub(2);
                assert_eq!((blocks, aheads), (inner, 4 * inner), "{cols}×{rows}");
            }
        }
    }

    #[test]
    fn tiling_caps_the_cell_count_by_the_number_of_circles() {
        let grid = Grid::tiling(DVec2::ZERO, DVec2::splat(1e6), 1e-3, 100, false);
        assert!(grid.len() <= 4 * 100 + 2 * 21, "{} cells", grid.len());
        assert_eq!(grid.cell.x * grid.cols as f64, 1e6);
    }

    #[test]
    fn members_join_and_leave_in_any_order() {
        let mut m = CellMembers::new(2, 4);
        for i in 0..4 {
            m.insert(i, i % 2);
        }
        assert_eq!(m.members(0).collect::<Vec<_>>(), [2, 0], "newest first");
        m.remove(2, 0);
        m.remove(1, 1);
        assert_eq!(m.members(0).collect::<Vec<_>>(), [0]);
        assert_eq!(m.members(1).collect::<Vec<_>>(), [3]);
        m.clear();
        assert_eq!(m.members(1).count(), 0);
    }
}
