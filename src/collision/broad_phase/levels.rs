//! Size levels for radii spanning decades: one grid sized for the largest circle would put
//! thousands of small circles in each cell, so circles are split into levels by size (a factor
//! of 4 per level), each level gets its own grid, and each circle also checks the cells of the
//! finer levels under it.

use std::ops::ControlFlow;

use bevy::math::DVec2;

use super::cells::{CellList, radius_range};
use super::scan::{single_level_pairs, sort_and_dedupe, visit_single_level};
use crate::base::arena::Arena;

/// Most size levels: a factor of 4 each, so 4⁶⁴ ≈ 3·10³⁸ between the smallest and largest
/// circle before the largest are lumped together (correct, just slower).
const MAX_LEVELS: usize = 64;

struct Level {
    members: Vec<u32>,
    cells: CellList,
    max_radius: f64,
}

/// Appends every overlapping pair `(i, j)`, `i < j`, of `circles` (centre, reach), sorted, with
/// `r_min` the smallest reach.
pub fn multi_level_pairs(
    arena: &Arena,
    circles: &[(DVec2, f64)],
    r_min: f64,
    pairs: &mut Vec<(u32, u32)>,
) {
    let start = pairs.len();
    let mut push = |i: u32, j: u32| {
        pairs.push((i, j));
        ControlFlow::Continue(())
    };
    // Within a level, the (parallel for large levels) listing scan.
    let levels = build_levels(circles, r_min, |cells, own, max_radius, members| {
        let mut local = Vec::new();
        single_level_pairs(cells, arena, own, max_radius, &mut local);
        for (a, b) in local {
            let (i, j) = (members[a as usize], members[b as usize]);
            push(i.min(j), i.max(j))?;
        }
        ControlFlow::Continue(())
    });
    if let ControlFlow::Continue(levels) = levels {
        let _ = visit_across_levels(&levels, arena, circles, &mut push);
    }
    // A box wider than a periodic grid visits some cells twice; keep each pair once.
    sort_and_dedupe(pairs, start);
}

/// [`multi_level_pairs`] as a serial visit that can stop early and lists nothing: each
/// overlapping pair `(i, j)`, `i < j`, goes to `visit` (a pair may come twice on a periodic
/// grid narrower than three cells).
pub fn visit_multi_level(
    arena: &Arena,
    circles: &[(DVec2, f64)],
    r_min: f64,
    visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> ControlFlow<()> {
    let levels = build_levels(circles, r_min, |cells, own, max_radius, members| {
        visit_single_level(cells, arena, own, max_radius, &mut |a, b| {
            let (i, j) = (members[a as usize], members[b as usize]);
            visit(i.min(j), i.max(j))
        })
    })?;
    visit_across_levels(&levels, arena, circles, visit)
}

/// The size levels of `circles`, each with its cell list built by `within`, which is handed the
/// level's cell list, its circles, their largest reach and their indices in `circles`, and
/// finds the pairs inside the level (stopping everything when it says so).
fn build_levels(
    circles: &[(DVec2, f64)],
    r_min: f64,
    mut within: impl FnMut(&mut CellList, &[(DVec2, f64)], f64, &[u32]) -> ControlFlow<()>,
) -> ControlFlow<(), Vec<Level>> {
    let mut levels: Vec<Level> = Vec::new();
    for members in split_levels(circles, r_min) {
        let own: Vec<(DVec2, f64)> = members.iter().map(|&i| circles[i as usize]).collect();
        let mut cells = CellList::default();
        let max_radius = radius_range(&own).1;
        within(&mut cells, &own, max_radius, &members)?;
        levels.push(Level {
            members,
            cells,
            max_radius,
        });
    }
    ControlFlow::Continue(levels)
}

/// The indices of `circles` by size level (a factor of 4 in radius per level above `r_min`).
fn split_levels(circles: &[(DVec2, f64)], r_min: f64) -> Vec<Vec<u32>> {
    // A ratio that overflows (a subnormal radius beside a normal one) is infinite, which `as`
    // saturates; the cap keeps the level index in range.
    let level_of =
        |r: f64| (((r / r_min).log2() / 2.0).floor().max(0.0) as usize).min(MAX_LEVELS - 1);
    let mut members: Vec<Vec<u32>> = Vec::new();
    for (i, &(_, r)) in circles.iter().enumerate() {
        let l = level_of(r);
        if members.len() <= l {
            members.resize(l + 1, Vec::new());
        }
        members[l].push(i as u32);
    }
    members
}

/// Each circle against the finer levels: the cells its reach could touch.
fn visit_across_levels(
    levels: &[Level],
    arena: &Arena,
    circles: &[(DVec2, f64)],
    visit: &mut impl FnMut(u32, u32) -> ControlFlow<()>,
) -> ControlFlow<()> {
    let mut flow = ControlFlow::Continue(());
    for (m, coarse) in levels.iter().enumerate() {
        for &a in &coarse.members {
            let (p, r) = circles[a as usize];
            for fine in &levels[..m] {
                if fine.members.is_empty() {
                    continue;
                }
                let reach = DVec2::splat(r + fine.max_radius);
                fine.cells.for_each_in_box(p - reach, p + reach, |k| {
                    let b = fine.members[fine.cells.order()[k] as usize];
                    let (q, s) = circles[b as usize];
                    if flow.is_continue() && arena.offset(p, q).length_squared() < (r + s) * (r + s)
                    {
                        flow = visit(a.min(b), a.max(b));
                    }
                });
                flow?;
            }
        }
    }
    ControlFlow::Continue(())
}
