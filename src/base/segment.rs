//! Segment walls inside the arena: [`Segment`] (a straight piece of wall, both faces solid, its
//! ends rounded by the circles that hit them), [`Segments`] (the scene's segments, a resource)
//! and [`SegmentCells`], the per-cell lists that let every solver look only at the segments
//! near a circle, so thousands of segments cost about what a few do.

use bevy::math::DVec2;
use bevy::prelude::*;
use serde::{Deserialize, Serialize};

use crate::base::arena::Arena;
use crate::base::error::FieldError;
use crate::base::grid::Grid;
use crate::base::range::check_vector;

/// Most segments a scene may declare: enough for detailed mazes and boards, few enough that the
/// per-cell lists stay small.
pub const MAX_SEGMENTS: usize = 100_000;

/// A straight wall from `a` to `b`, solid on both faces and at both ends.
#[derive(Reflect, Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// One end.
    pub a: DVec2,
    /// The other end.
    pub b: DVec2,
}

impl Segment {
    /// The segment from `a` to `b`.
    pub fn new(a: DVec2, b: DVec2) -> Self {
        Self { a, b }
    }

    /// The point of the segment nearest to `p`.
    ///
    /// ```
    /// use bevy::math::DVec2;
    /// use moving_circles::base::segment::Segment;
    ///
    /// let s = Segment::new(DVec2::ZERO, DVec2::new(2.0, 0.0));
    /// assert_eq!(s.closest_point(DVec2::new(0.5, 3.0)), DVec2::new(0.5, 0.0));
    /// assert_eq!(s.closest_point(DVec2::new(-1.0, 1.0)), DVec2::ZERO); // past an end
    /// ```
    #[inline]
    pub fn closest_point(&self, p: DVec2) -> DVec2 {
        let d = self.b - self.a;
        let len2 = d.length_squared();
        if len2 == 0.0 {
            return self.a;
        }
        let t = ((p - self.a).dot(d) / len2).clamp(0.0, 1.0);
        self.a + d * t
    }

    /// Distance from `p` to the segment.
    #[inline]
    pub fn distance(&self, p: DVec2) -> f64 {
        (p - self.closest_point(p)).length()
    }

    /// Where a circle centred at `p` moving at `velocity` touches the segment: the nearest
    /// point, the unit normal from it out towards `p`, and the distance. A centre on the segment
    /// is sent back the way it came (the normal faces against the velocity).
    pub fn contact(&self, p: DVec2, velocity: DVec2) -> (DVec2, DVec2, f64) {
        let point = self.closest_point(p);
        let offset = p - point;
        let distance = offset.length();
        let out = if distance > 0.0 {
            offset / distance
        } else {
            let n = self.normal();
            let n = if n == DVec2::ZERO {
                -velocity.normalize_or(DVec2::Y)
            } else {
                n
            };
            if velocity.dot(n) > 0.0 { -n } else { n }
        };
        (point, out, distance)
    }

    /// Unit normal to the segment (`a → b` turned a quarter left); zero for a point.
    pub fn normal(&self) -> DVec2 {
        (self.b - self.a).perp().normalize_or_zero()
    }

    /// Length.
    pub fn length(&self) -> f64 {
        (self.b - self.a).length()
    }
}

/// The segment walls of the arena, in the order the scene gives them (a
/// [`WallHit`](crate::base::hits::WallHit) names one by its index here). Empty by default: no segment
/// effect is scheduled then.
#[derive(Resource, Reflect, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[reflect(Resource, Debug)]
pub struct Segments(pub Vec<Segment>);

impl Segments {
    /// The segments of polylines, each given by its corner points in order (two points: one
    /// segment).
    ///
    /// ```
    /// use bevy::math::DVec2;
    /// use moving_circles::base::segment::Segments;
    ///
    /// let v = Segments::from_polylines(&[vec![DVec2::new(-1.0, 1.0), DVec2::ZERO, DVec2::ONE]]);
    /// assert_eq!(v.0.len(), 2);
    /// ```
    pub fn from_polylines(polylines: &[Vec<DVec2>]) -> Self {
        Self(
            polylines
                .iter()
                .flat_map(|line| line.windows(2).map(|w| Segment::new(w[0], w[1])))
                .collect(),
        )
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Whether these segments fit `arena`: no more than [`MAX_SEGMENTS`], every end inside it,
    /// and an arena that is not periodic (there a segment would have to wrap). Fields are
    /// named `segments[k].a` / `.b`, `k` counting segments as a [`WallHit`] does.
    ///
    /// [`WallHit`]: crate::base::hits::WallHit
    pub fn check(&self, arena: &Arena) -> Result<(), FieldError> {
        if self.0.len() > MAX_SEGMENTS {
            let n = self.0.len();
            let why = format!("{n} segments; at most {MAX_SEGMENTS} are supported");
            return Err(FieldError::new("segments", why));
        }
        if !self.is_empty() && arena.is_periodic() {
            let why = "segment walls need an arena with walls or an open one, not a periodic one";
            return Err(FieldError::new("segments", why));
        }
        for (k, s) in self.0.iter().enumerate() {
            check_end(&format!("segments[{k}].a"), s.a, arena)?;
            check_end(&format!("segments[{k}].b"), s.b, arena)?;
        }
        Ok(())
    }
}

/// Whether `p`, the end of a segment wall called `field`, is a finite point inside `arena`.
pub fn check_end(field: &str, p: DVec2, arena: &Arena) -> Result<(), FieldError> {
    check_vector(field, p)?;
    if !(p.cmpge(arena.min).all() && p.cmple(arena.max).all()) {
        let (min, max) = (arena.min, arena.max);
        let why = format!("{p} is outside the arena, which spans {min} to {max}");
        return Err(FieldError::new(field, why));
    }
    Ok(())
}

/// For each cell of a `Grid`, the segments that pass within `margin` of it (and possibly a
/// few more: a cell takes a segment when it is within `margin` plus half the cell's diagonal
/// of the cell's centre). A circle of radius at most `margin` whose centre is in a cell can
/// only touch the segments of that cell; one larger than a cell looks at the cells its bounding
/// box covers ([`SegmentCells::near`]).
#[derive(Clone, Debug, Default)]
pub struct SegmentCells {
    grid: Grid,
    /// `start[c]..start[c + 1]` indexes `members` for cell `c`.
    start: Vec<u32>,
    members: Vec<u32>,
}

impl SegmentCells {
    /// Lists `segments` in the cells of `grid`, each in the cells within `margin` of it.
    pub fn build(segments: &[Segment], grid: Grid, margin: f64) -> Self {
        let half_diagonal = 0.5 * grid.cell.length();
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for (k, s) in segments.iter().enumerate() {
            let reach = margin + half_diagonal;
            let lo = s.a.min(s.b) - DVec2::splat(margin);
            let hi = s.a.max(s.b) + DVec2::splat(margin);
            let (x0, y0) = grid.cell_of(lo);
            let (x1, y1) = grid.cell_of(hi);
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let centre = grid.origin + (DVec2::new(x as f64, y as f64) + 0.5) * grid.cell;
                    if s.distance(centre) <= reach {
                        pairs.push((grid.index(x, y) as u32, k as u32));
                    }
                }
            }
        }
        pairs.sort_unstable();
        let mut start = vec![0u32; grid.len() + 1];
        for &(c, _) in &pairs {
            start[c as usize + 1] += 1;
        }
        for c in 0..grid.len() {
            start[c + 1] += start[c];
        }
        Self {
            grid,
            start,
            members: pairs.into_iter().map(|(_, k)| k).collect(),
        }
    }

    /// Lists for looking up the segments near a circle anywhere in `arena`: cells about one
    /// segment long, at most about four per segment. An open arena's segments may lie outside
    /// its rectangle: the cells then cover them too (a circle beyond every cell is looked up
    /// in the nearest edge cells, which list every segment near that edge).
    pub fn over_arena(segments: &[Segment], arena: &Arena) -> Self {
        let total: f64 = segments.iter().map(Segment::length).sum();
        let mean = total / segments.len().max(1) as f64;
        let (mut lo, mut hi) = (arena.min, arena.max);
        if arena.is_open() {
            for s in segments {
                (lo, hi) = (lo.min(s.a).min(s.b), hi.max(s.a).max(s.b));
            }
        }
        let grid = Grid::tiling(lo, hi - lo, mean, segments.len(), false);
        Self::build(segments, grid, 0.0)
    }

    /// Whether a circle of `radius` at `centre` overlaps one of `segments` (the ones these
    /// lists were built for) by more than rounding (a billionth of its radius), and which.
    pub fn first_touched(&self, segments: &[Segment], centre: DVec2, radius: f64) -> Option<u32> {
        let mut found = None;
        let reach = radius * (1.0 - 1e-9);
        self.near(centre, radius, |k| {
            if found.is_none() && segments[k as usize].distance(centre) < reach {
                found = Some(k);
            }
        });
        found
    }

    /// The grid the lists are kept on.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The segments listed in cell `c`.
    #[inline]
    pub fn in_cell(&self, c: usize) -> &[u32] {
        if self.members.is_empty() {
            // No segment: nothing to look up (the event engine asks at every event).
            return &[];
        }
        match self.start.get(c..c + 2) {
            Some(&[from, to]) => &self.members[from as usize..to as usize],
            _ => &[],
        }
    }

    /// Calls `visit` with every segment listed in a cell the box `centre ± reach` covers (a
    /// segment in several such cells is visited once per cell).
    #[inline]
    pub fn near(&self, centre: DVec2, reach: f64, mut visit: impl FnMut(u32)) {
        if self.members.is_empty() {
            return;
        }
        let (x0, y0) = self.grid.cell_of(centre - DVec2::splat(reach));
        let (x1, y1) = self.grid.cell_of(centre + DVec2::splat(reach));
        for y in y0..=y1 {
            for x in x0..=x1 {
                for &k in self.in_cell(self.grid.index(x, y)) {
                    visit(k);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_list_every_segment_a_circle_in_them_can_touch() {
        // A diagonal segment across a 10×10 grid of unit cells: with margin 0.3 every cell
        // whose points come within 0.3 of it lists it, and cells far away do not.
        let grid = Grid::square(DVec2::ZERO, 1.0, 10, 10);
        let s = Segment::new(DVec2::new(0.5, 0.5), DVec2::new(9.5, 6.0));
        let cells = SegmentCells::build(&[s], grid, 0.3);
        for y in 0..100 {
            for x in 0..100 {
                let p = DVec2::new(x as f64 + 0.05, y as f64 + 0.05) / 10.0;
                let c = grid.cell_of(p);
                if s.distance(p) <= 0.3 {
                    assert_eq!(cells.in_cell(grid.index(c.0, c.1)), &[0], "{p}");
                }
            }
        }
        assert!(cells.in_cell(grid.index(0, 9)).is_empty());
        assert!(cells.in_cell(grid.index(9, 0)).is_empty());
        let listed = (0..grid.len())
            .filter(|&c| !cells.in_cell(c).is_empty())
            .count();
        assert!(
            listed < 40,
            "a diagonal lists a band of cells, not its box: {listed}"
        );
    }

    #[test]
    fn a_zero_length_segment_is_a_point() {
        let s = Segment::new(DVec2::ONE, DVec2::ONE);
        assert_eq!(s.closest_point(DVec2::ZERO), DVec2::ONE);
        assert_eq!(s.normal(), DVec2::ZERO);
    }
}
