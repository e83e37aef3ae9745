//! [`PairList`]: the broad phase's pairs kept from step to step (a Verlet list). Made with
//! every reach grown by a skin, the list holds every pair that can overlap until some circle
//! has moved, or grown its reach, by most of its skin; until then a step bins the circles (for
//! their order) but scans no cells. Box2D's enlarged boxes serve the same end. What a step is
//! handed depends only on the circles now, never on when the list was made: the pairs whose
//! reaches overlap now, in the order a fresh broad phase finds them (with one grid), so a
//! solver that takes them one after another works through neighbours together, and gets the
//! same result.

use bevy::math::DVec2;

use super::broad_phase::{CellList, needs_levels, overlapping_pairs, radius_range};
use crate::base::arena::Arena;

/// How far past its reach (as a fraction of it) a list is made to hold a circle's pairs, for
/// callers with no reason to choose otherwise: a settled circle moves so little that the list
/// lasts many steps. Box2D enlarges its boxes by 0.1 m, a fifth of a radius of 0.5 m.
pub const SKIN: f64 = 0.25;

/// Part of the skin a circle may use up before the list is made again: the rest is a cushion
/// that keeps rounding in the distances from ever dropping a pair.
const USABLE_SKIN: f64 = 0.75;

/// The broad phase's pairs kept from step to step.
#[derive(Default)]
pub struct PairList {
    /// Each circle's centre when the list was made, and the reach plus distance moved it may
    /// have before the list is made again.
    made: Vec<(DVec2, f64)>,
    /// The pairs `(i, j)`, `i < j`, whose grown reaches overlapped when the list was made.
    pairs: Vec<(u32, u32)>,
    cells: CellList,
    /// Each circle's place in the cell order `sequence` follows (`u32::MAX` for a circle
    /// with a non-finite centre, which overlaps nothing).
    rank: Vec<u32>,
    /// The list's pairs in the order they are handed over, and the same sorted by their
    /// later circle's place only (the first pass of the sort).
    sequence: Vec<(u32, u32)>,
    by_later: Vec<(u32, u32)>,
    /// The counting sorts' pairs per place, then where each place's pairs go.
    counts: Vec<u32>,
    /// The cell order `sequence` was put in order for.
    sequenced_for: Vec<u32>,
    grown: Vec<(DVec2, f64)>,
    /// A fresh broad phase's pairs, when the list is not kept.
    fresh: Vec<(u32, u32)>,
    /// How many times the list has been made.
    made_count: u64,
}

impl PairList {
    /// Hands `visit` every pair `(i, j)`, `i < j`, of `circles` (centre, reach) whose reaches
    /// overlap in `arena` (centre distance below their sum; the minimum image on a periodic
    /// arena): what [`overlapping_pairs`] finds.
    ///
    /// With `keep`, from the list, in the order the broad phase finds them with one grid (radii
    /// within [`super::broad_phase::MULTI_LEVEL_RATIO`], a periodic arena at least three cells
    /// across): the cell order now (cells twice the largest reach wide; the smallest, when
    /// radii need more than one grid), by the place of whichever of the two comes first in it,
    /// then of the other. The list is made again, each reach grown by `skin` times itself, when
    /// a circle has moved too far, grown its reach or come or gone since it was last made.
    ///
    /// Without `keep` (circles too fast for a list to last), by a fresh broad phase, in its
    /// order; the list is left as it is.
    pub fn for_each_overlapping(
        &mut self,
        arena: &Arena,
        circles: &[(DVec2, f64)],
        (keep, skin): (bool, f64),
        mut visit: impl FnMut(usize, usize),
    ) {
        if !keep {
            self.fresh.clear();
            overlapping_pairs(&mut self.cells, arena, circles, &mut self.fresh);
            for &(i, j) in &self.fresh {
                visit(i as usize, j as usize);
            }
            return;
        }
        let made = self.refresh(arena, circles, skin);
        // Cells as the broad phase's with one grid; with radii too wide for one, as wide as
        // the smallest circles, so that the order still follows where the circles are.
        let (smallest, widest) = radius_range(circles);
        let cell = 2.0
            * if needs_levels((smallest, widest)) {
                smallest
            } else {
                widest
            };
        if arena.is_periodic() {
            let (min, size) = (arena.min, arena.size());
            self.cells.rebuild_periodic(circles, min, size, cell);
        } else {
            self.cells.rebuild(circles, cell);
        }
        // The order of the pairs changes only with the list or with the cell order.
        if made || self.cells.order() != self.sequenced_for {
            self.sequence_pairs(circles.len());
        }
        visit_overlapping(arena, circles, &self.sequence, visit);
    }

    /// Hands `visit` every pair `(i, j)`, `i < j`, of `circles` (centre, reach) whose reaches
    /// overlap in `arena`, as [`PairList::for_each_overlapping`] with `keep`, in an order for
    /// callers whose result does not depend on it (as the list keeps them), which saves
    /// binning the circles.
    pub fn for_each_overlapping_in_any_order(
        &mut self,
        arena: &Arena,
        circles: &[(DVec2, f64)],
        skin: f64,
        visit: impl FnMut(usize, usize),
    ) {
        self.refresh(arena, circles, skin);
        visit_overlapping(arena, circles, &self.pairs, visit);
    }

    /// Makes the list again, each reach grown by `skin` times itself, if it no longer holds
    /// every overlapping pair of `circles`; returns whether it did.
    fn refresh(&mut self, arena: &Arena, circles: &[(DVec2, f64)], skin: f64) -> bool {
        let stale = !self.holds(arena, circles);
        if stale {
            self.make(arena, circles, skin);
        }
        stale
    }

    /// Puts the list's pairs in the order they are handed over for the cell order now: by
    /// the place of the first of the two in it, then of the other (two counting sorts, the
    /// first by the later place, the second, which keeps that order, by the earlier).
    fn sequence_pairs(&mut self, n: usize) {
        let order = self.cells.order();
        self.sequenced_for.clear();
        self.sequenced_for.extend_from_slice(order);
        self.rank.clear();
        self.rank.resize(n, u32::MAX);
        for (k, &i) in order.iter().enumerate() {
            self.rank[i as usize] = k as u32;
        }
        let rank = &self.rank;
        // Both places, first and later; none for a circle without one (a non-finite centre
        // overlaps nothing).
        let places = |&(i, j): &(u32, u32)| {
            let (a, b) = (rank[i as usize], rank[j as usize]);
            let (first, later) = (a.min(b), a.max(b));
            (later != u32::MAX).then_some((first, later))
        };
        let (places_now, counts) = (order.len(), &mut self.counts);
        let by_later = |pair: &(u32, u32)| places(pair).map(|(_, later)| later);
        counting_sort(
            &self.pairs,
            by_later,
            places_now,
            counts,
            &mut self.by_later,
        );
        let by_first = |pair: &(u32, u32)| places(pair).map(|(first, _)| first);
        counting_sort(
            &self.by_later,
            by_first,
            places_now,
            counts,
            &mut self.sequence,
        );
    }

    /// How many times the list has been made since it was created (what the tests watch).
    #[cfg(test)]
    pub fn made_count(&self) -> u64 {
        self.made_count
    }

    /// Whether the list still holds every overlapping pair of `circles`: the same number of
    /// circles, each within its allowance of where it was (a NaN never is).
    fn holds(&self, arena: &Arena, circles: &[(DVec2, f64)]) -> bool {
        self.made.len() == circles.len()
            && self.made.iter().zip(circles).all(|(&(c, most), &(p, r))| {
                let room = most - r;
                room >= 0.0 && arena.offset(c, p).length_squared() <= room * room
            })
    }

    /// Makes the list for `circles`, each reach grown by `skin` times itself.
    fn make(&mut self, arena: &Arena, circles: &[(DVec2, f64)], skin: f64) {
        self.made_count += 1;
        self.grown.clear();
        let grown = circles.iter().map(|&(p, r)| (p, r * (1.0 + skin)));
        self.grown.extend(grown);
        self.made.clear();
        let made = circles
            .iter()
            .map(|&(p, r)| (p, r * (1.0 + USABLE_SKIN * skin)));
        self.made.extend(made);
        self.pairs.clear();
        overlapping_pairs(&mut self.cells, arena, &self.grown, &mut self.pairs);
    }
}

/// Hands `visit` each of `pairs`, in their order, whose circles' reaches overlap in `arena`.
#[inline]
fn visit_overlapping(
    arena: &Arena,
    circles: &[(DVec2, f64)],
    pairs: &[(u32, u32)],
    mut visit: impl FnMut(usize, usize),
) {
    for &(i, j) in pairs {
        let ((p, r), (q, s)) = (circles[i as usize], circles[j as usize]);
        if arena.offset(p, q).length_squared() < (r + s) * (r + s) {
            visit(i as usize, j as usize);
        }
    }
}

/// `pairs` sorted by `key` (below `keys`) into `out`, pairs of equal keys in their order
/// there, pairs without a key left out; `counts` is scratch.
fn counting_sort(
    pairs: &[(u32, u32)],
    key: impl Fn(&(u32, u32)) -> Option<u32>,
    keys: usize,
    counts: &mut Vec<u32>,
    out: &mut Vec<(u32, u32)>,
) {
    counts.clear();
    counts.resize(keys + 1, 0);
    for k in pairs.iter().filter_map(&key) {
        counts[k as usize + 1] += 1;
    }
    for k in 0..keys {
        counts[k + 1] += counts[k];
    }
    out.clear();
    out.resize(counts[keys] as usize, (0, 0));
    for pair in pairs {
        if let Some(k) = key(pair) {
            let slot = &mut counts[k as usize];
            out[*slot as usize] = *pair;
            *slot += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::base::arena::Boundary;

    /// What a fresh broad phase finds, sorted.
    fn fresh(arena: &Arena, circles: &[(DVec2, f64)]) -> Vec<(usize, usize)> {
        let mut pairs = Vec::new();
        overlapping_pairs(&mut CellList::default(), arena, circles, &mut pairs);
        let mut pairs: Vec<_> = pairs
            .into_iter()
            .map(|(i, j)| (i as usize, j as usize))
            .collect();
        pairs.sort_unstable();
        pairs
    }

    #[test]
    fn a_kept_list_hands_over_what_a_new_one_and_the_broad_phase_do_in_their_order() {
        // Radii of one grid, and radii over a decade plus a large circle (levels).
        let cases = [
            (Boundary::Walls, 0.3..0.6, None),
            (Boundary::Periodic, 0.3..0.6, None),
            (Boundary::Walls, 0.05..0.6, Some(2.5)),
            (Boundary::Periodic, 0.05..0.6, Some(2.5)),
        ];
        for (boundary, radii, large) in cases {
            let arena = Arena {
                min: DVec2::ZERO,
                max: DVec2::splat(20.0),
                boundary,
            };
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            let mut circles: Vec<(DVec2, f64)> = (0..400)
                .map(|_| {
                    let p = DVec2::new(rng.random_range(0.0..20.0), rng.random_range(0.0..20.0));
                    (p, rng.random_range(radii.clone()))
                })
                .collect();
            if let Some(r) = large {
                circles[0].1 = r;
            }
            let (mut list, mut any_order) = (PairList::default(), PairList::default());
            for step in 0..300 {
                // Drifts of up to a fiftieth of a radius, a reach that grows now and then, and
                // a jump across the arena (wrapped on the periodic one) every 50 steps.
                for (k, (p, r)) in circles.iter_mut().enumerate() {
                    let drift =
                        DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    *p += drift * 0.02 * *r;
                    *p = arena.wrap(*p);
                    if (k + step) % 97 == 0 {
                        *r *= 1.01;
                    }
                }
                if step % 50 == 49 {
                    circles[step % 400].0 =
                        arena.wrap(circles[step % 400].0 + DVec2::new(9.7, 3.1));
                }
                let mut handed = Vec::new();
                let kept = (true, 0.25);
                list.for_each_overlapping(&arena, &circles, kept, |i, j| handed.push((i, j)));
                // A list made just now hands the same pairs in the same order: what a step is
                // handed does not depend on when the list was made.
                let mut new = Vec::new();
                PairList::default()
                    .for_each_overlapping(&arena, &circles, kept, |i, j| new.push((i, j)));
                assert_eq!(handed, new, "{boundary:?}, step {step}");
                // Without keeping, the broad phase's own order: the same one in a walled box.
                let mut afresh = Vec::new();
                let mut other = PairList::default();
                other.for_each_overlapping(&arena, &circles, (false, 0.25), |i, j| {
                    afresh.push((i, j))
                });
                assert_eq!(other.made_count(), 0);
                if boundary == Boundary::Walls && large.is_none() {
                    assert_eq!(handed, afresh, "step {step}");
                }
                // In any order: the same pairs, from a list kept alongside.
                let mut unordered = Vec::new();
                any_order.for_each_overlapping_in_any_order(&arena, &circles, 0.25, |i, j| {
                    unordered.push((i, j))
                });
                handed.sort_unstable();
                afresh.sort_unstable();
                unordered.sort_unstable();
                assert_eq!(handed, fresh(&arena, &circles), "{boundary:?}, step {step}");
                assert_eq!(afresh, handed, "{boundary:?}, step {step}");
                assert_eq!(unordered, handed, "{boundary:?}, step {step}");
            }
            let made = list.made_count();
            assert!(
                (2..150).contains(&made),
                "{boundary:?}, {large:?}: made {made} times"
            );
        }
    }

    #[test]
    fn the_list_is_made_again_when_circles_come_or_a_centre_is_nan() {
        let arena = Arena {
            min: DVec2::ZERO,
            max: DVec2::splat(10.0),
            boundary: Boundary::Walls,
        };
        let mut circles = vec![(DVec2::new(1.0, 1.0), 0.5), (DVec2::new(1.8, 1.0), 0.5)];
        let mut list = PairList::default();
        let mut handed = Vec::new();
        list.for_each_overlapping(&arena, &circles, (true, 0.25), |i, j| handed.push((i, j)));
        list.for_each_overlapping(&arena, &circles, (true, 0.25), |i, j| handed.push((i, j)));
        assert_eq!(
            (handed.as_slice(), list.made_count()),
            (&[(0, 1), (0, 1)][..], 1)
        );
        circles.push((DVec2::new(2.5, 1.0), 0.5));
        handed.clear();
        list.for_each_overlapping(&arena, &circles, (true, 0.25), |i, j| handed.push((i, j)));
        assert_eq!(
            (handed.as_slice(), list.made_count()),
            (&[(0, 1), (1, 2)][..], 2)
        );
        circles[2].0.x = f64::NAN;
        handed.clear();
        list.for_each_overlapping(&arena, &circles, (true, 0.25), |i, j| handed.push((i, j)));
        list.for_each_overlapping(&arena, &circles, (true, 0.25), |_, _| {});
        assert_eq!((handed.as_slice(), list.made_count()), (&[(0, 1)][..], 4));
    }
}
