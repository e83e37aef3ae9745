//! Circles too large for the cells: when a few circles are far wider than the cells the rest
//! of the circles want (two boulders in a fine sand), they stay out of the cell lists, every
//! circle looks at them whenever it looks at its neighbours, and each of them looks at the
//! block of cells its radius reaches. The cells then stay sized for the many, not the few.

use super::EventEngine;
use crate::base::circle::CircleState;
use crate::base::collision_layers::{CollisionLayers, can_meet};
use crate::base::grid::Grid;

/// Most circles kept out of the cells: every prediction looks at all of them, so past a handful
/// one grid for all (cells a largest diameter wide) is cheaper.
pub const MAX_LARGE: usize = 8;

/// The circles to keep out of cells about `width` wide (those wider than it, if at most
/// [`MAX_LARGE`]), in order, and the largest radius of the circles that stay in the cells. Only
/// circles that [`can_meet`] another under `layers` count: one that meets none stays in
/// the cells however wide it is, since no circle ever looks for it there.
pub(super) fn large_circles(
    circles: &[CircleState],
    width: f64,
    layers: &[CollisionLayers],
) -> (Vec<u32>, f64) {
    let large: Vec<u32> = (0..circles.len() as u32)
        .filter(|&i| can_meet(layers, i as usize) && 2.0 * circles[i as usize].radius > width)
        .collect();
    let large = if large.len() <= MAX_LARGE && large.len() < circles.len() {
        large
    } else {
        Vec::new()
    };
    let in_cells = circles
        .iter()
        .enumerate()
        .filter(|&(i, _)| can_meet(layers, i) && !large.contains(&(i as u32)))
        .map(|(_, c)| c.radius)
        .fold(0.0, f64::max);
    (large, in_cells)
}

/// How many cells around its own a large circle of radius `radius` looks at, along each axis, to
/// find every circle in the cells (of radius at most `in_cells`) it can touch: one more than
/// the touching distance spans, for centres on a cell's edge by rounding.
pub(super) fn reach(grid: &Grid, radius: f64, in_cells: f64) -> u32 {
    ((radius + in_cells) / grid.cell.min_element()).floor() as u32 + 1
}

/// The cells within `reach` of cell `at` along an axis of `count` cells: clipped at the edges of
/// a walled grid, wrapped (each once) on a periodic one.
pub(super) fn span(
    at: usize,
    reach: u32,
    count: usize,
    periodic: bool,
) -> impl Iterator<Item = usize> + Clone {
    let reach = reach as usize;
    let (from, to) = if periodic && 2 * reach + 1 >= count {
        (0, count - 1)
    } else if periodic {
        (at + count - reach, at + count + reach)
    } else {
        (at.saturating_sub(reach), (at + reach).min(count - 1))
    };
    (from..=to).map(move |k| k % count)
}

impl EventEngine {
    /// How many cells circle `i` looks at around its own, if it is a large circle.
    #[inline]
    pub(super) fn large_reach(&self, i: usize) -> Option<u32> {
        let at = self.large.iter().position(|&b| b as usize == i)?;
        Some(self.reach[at])
    }

    /// Looks at every circle a large circle `i` can reach and schedules its soonest event.
    pub(super) fn predict_large(&mut self, i: usize, reach: u32) {
        let (x, y) = (self.cell_x[i] as usize, self.cell_y[i] as usize);
        let g = self.grid;
        let columns = span(x, reach, g.cols, g.periodic);
        let cells = span(y, reach, g.rows, g.periodic)
            .flat_map(move |row| columns.clone().map(move |col| row * g.cols + col));
        self.best_pair[i] = self.scan(i, cells);
        self.schedule(i);
    }

    /// After large circle `i` crossed into a new cell along `axis`: the row or column of cells
    /// its reach newly takes in.
    pub(super) fn large_after_crossing(&mut self, i: usize, axis: usize, up: bool, reach: u32) {
        let (x, y) = (self.cell_x[i] as usize, self.cell_y[i] as usize);
        let g = self.grid;
        let (at, count, across, across_count) = if axis == 0 {
            (x, g.cols, y, g.rows)
        } else {
            (y, g.rows, x, g.cols)
        };
        let r = reach as usize;
        // The far side of the reach along `axis`, if it is not a cell the reach held already.
        let line = if g.periodic {
            (2 * r + 1 < count).then(|| {
                if up {
                    (at + r) % count
                } else {
                    (at + count - r) % count
                }
            })
        } else if up {
            (at + r < count).then_some(at + r)
        } else {
            at.checked_sub(r)
        };
        let best = self.best_pair[i];
        if let Some(line) = line {
            let cells = span(across, reach, across_count, g.periodic).map(move |k| {
                if axis == 0 {
                    k * g.cols + line
                } else {
                    line * g.cols + k
                }
            });
            let found = self.scan(i, cells);
            if found.time < best.time {
                self.best_pair[i] = found;
            }
        }
        self.schedule(i);
    }
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::base::arena::{Arena, Boundary};

    /// Two large circles (radii 0.1 and 0.06) in a gas of 300 of radius 0.004 on a lattice,
    /// with pseudo-random velocities.
    fn boulders_in_sand() -> Vec<CircleState> {
        let mut circles = vec![
            CircleState::new(DVec2::new(0.3, 0.3), DVec2::new(0.2, 0.1), 0.1),
            CircleState::new(DVec2::new(0.7, 0.6), DVec2::new(-0.1, 0.3), 0.06),
        ];
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut next = || rng.random_range(-0.5..0.5);
        for k in 0..400 {
            let p = DVec2::new((k % 20) as f64 + 0.5, (k / 20) as f64 + 0.5) / 20.0;
            let clear = circles[..2]
                .iter()
                .all(|c| c.position.distance(p) > c.radius + 0.01);
            if clear && circles.len() < 302 {
                circles.push(CircleState::new(p, DVec2::new(next(), next()), 0.004));
            }
        }
        circles
    }

    #[test]
    fn large_circles_out_of_the_cells_change_no_trajectory() {
        // Cells 0.02 wide keep the two large circles out; cells 0.25 wide hold them. Every time
        // is worked out from reference points, so both give the same run bit for bit, if no
        // pair is missed.
        let circles = boulders_in_sand();
        for boundary in [Boundary::Walls, Boundary::Periodic] {
            let arena = Arena::unit_square(boundary);
            let run = |width: f64| {
                let mut engine = EventEngine::with_cells(&circles, &arena, &[], (1.0, 1.0), width);
                let large = engine.large.clone();
                engine.advance_to(4.0, u64::MAX).unwrap();
                let state: Vec<_> = (0..engine.len())
                    .map(|i| (engine.position(i), engine.velocity(i)))
                    .collect();
                (large, engine.stats().pair_collisions, state)
            };
            let (apart, together) = (run(0.02), run(0.25));
            assert_eq!((apart.0, together.0), (vec![0, 1], vec![]), "{boundary:?}");
            assert!(apart.1 > 1000, "{boundary:?}: {} collisions", apart.1);
            assert_eq!(apart.1, together.1, "{boundary:?}: collision counts");
            assert!(apart.2 == together.2, "{boundary:?}: the states differ");
            // The large circles were hit many times.
            assert!(apart.2[0].1 != circles[0].velocity && apart.2[1].1 != circles[1].velocity);
        }
    }

    #[test]
    fn an_engine_with_large_circles_restores_bit_for_bit() {
        let circles = boulders_in_sand();
        let arena = Arena::unit_square(Boundary::Periodic);
        let mut original = EventEngine::new(&circles, &arena, &[], 1.0, 1.0);
        assert_eq!(
            original.large,
            vec![0, 1],
            "a dilute gas keeps them out of its cells"
        );
        original.advance_to(1.0, u64::MAX).unwrap();
        let now: Vec<_> = circles
            .iter()
            .enumerate()
            .map(|(i, c)| CircleState {
                position: original.position(i),
                velocity: original.velocity(i),
                ..*c
            })
            .collect();
        let mut restored = EventEngine::restore(
            original.snapshot(),
            &now,
            &arena,
            &[],
            (1.0, 1.0),
            DVec2::ZERO,
            crate::solvers::exact::engine::Roughness::SMOOTH,
            true,
        )
        .unwrap();
        original.advance_to(3.0, u64::MAX).unwrap();
        restored.advance_to(3.0, u64::MAX).unwrap();
        assert_eq!(restored.snapshot(), original.snapshot());
    }

    /// An elastic engine of `circles` without gravity, with their `layers`.
    fn elastic(
        circles: &[CircleState],
        arena: &Arena,
        layers: Vec<CollisionLayers>,
    ) -> EventEngine {
        EventEngine::build_until(circles, arena, &[], (1.0, 1.0), (None, &[]), layers, || {
            false
        })
        .unwrap()
    }

    #[test]
    fn circles_that_meet_none_leave_the_cells_as_they_are_without_them() {
        // The sand of `boulders_in_sand` without its boulders, and twelve zones of radius 0.15
        // that meet nothing (sensors): the cells stay sized for the sand, no zone is kept out
        // of them, and the sand moves bit for bit as it does alone.
        let sand = boulders_in_sand().split_off(2);
        let zones = (0..12).map(|k| {
            let p = DVec2::new(0.15 + 0.07 * k as f64, 0.2 + 0.05 * (k % 5) as f64);
            CircleState::new(p, DVec2::new(0.1, -0.05), 0.15)
        });
        let all: Vec<CircleState> = sand.iter().copied().chain(zones).collect();
        let layers: Vec<CollisionLayers> = (0..all.len())
            .map(|i| {
                if i < sand.len() {
                    CollisionLayers::DEFAULT
                } else {
                    CollisionLayers::NONE
                }
            })
            .collect();
        for boundary in [Boundary::Walls, Boundary::Periodic] {
            let arena = Arena::unit_square(boundary);
            let build = |circles: &[CircleState], layers| elastic(circles, &arena, layers);
            let mut alone = build(&sand, Vec::new());
            let mut beside = build(&all, layers.clone());
            assert_eq!(beside.grid, alone.grid, "{boundary:?}");
            assert!(beside.large.is_empty(), "{boundary:?}");
            // As plain circles the zones widen the cells past twice their radius.
            let plain = build(&all, Vec::new());
            assert!(plain.grid.cell.min_element() >= 0.3, "{boundary:?}");
            alone.advance_to(4.0, u64::MAX).unwrap();
            beside.advance_to(4.0, u64::MAX).unwrap();
            assert!(alone.stats().pair_collisions > 200, "{boundary:?}");
            assert_eq!(
                alone.stats().pair_collisions,
                beside.stats().pair_collisions,
                "{boundary:?}"
            );
            for i in 0..sand.len() {
                assert!(
                    alone.position(i) == beside.position(i)
                        && alone.velocity(i) == beside.velocity(i),
                    "{boundary:?}: circle {i}"
                );
            }
        }
    }

    #[test]
    fn a_wide_circle_that_comes_to_meet_others_gets_cells_sized_for_it() {
        // A zone of radius 0.3 built meeting nothing sits in cells sized for the sand; once its
        // layers let it meet, the cells are laid out again and a grain flying at it bounces off
        // it instead of passing through.
        let mut circles = boulders_in_sand().split_off(2);
        circles.push(CircleState::new(DVec2::new(0.5, 0.5), DVec2::ZERO, 0.3));
        circles.push(CircleState::new(
            DVec2::new(0.5, 0.05),
            DVec2::new(0.0, 1.0),
            0.004,
        ));
        let (zone, grain) = (circles.len() - 2, circles.len() - 1);
        for c in &mut circles[..zone] {
            // The sand out of the way: at rest, far from the grain's path.
            c.velocity = DVec2::ZERO;
            if (c.position.x - 0.5).abs() < 0.05 || c.position.distance(DVec2::splat(0.5)) < 0.32 {
                c.position.x = 0.97;
            }
        }
        let arena = Arena::unit_square(Boundary::Walls);
        let mut layers = vec![CollisionLayers::DEFAULT; circles.len()];
        layers[zone] = CollisionLayers::NONE;
        let mut engine = elastic(&circles, &arena, layers);
        assert!(engine.grid.cell.max_element() < 0.3);
        engine.set_layers(vec![CollisionLayers::DEFAULT; circles.len()]);
        engine.advance_to(0.5, u64::MAX).unwrap();
        // The grain meets the zone's edge at y = 0.196 (t ≈ 0.146) and flies back down.
        assert!(engine.velocity(grain).y < 0.0, "{}", engine.velocity(grain));
        assert!(engine.position(grain).distance(engine.position(zone)) >= 0.304 - 1e-12);
    }

    #[test]
    fn spans_clip_at_walls_and_wrap_each_cell_once() {
        let of = |at, reach, count, periodic| span(at, reach, count, periodic).collect::<Vec<_>>();
        assert_eq!(of(1, 2, 10, false), vec![0, 1, 2, 3]);
        assert_eq!(of(8, 2, 10, false), vec![6, 7, 8, 9]);
        assert_eq!(of(1, 2, 10, true), vec![9, 0, 1, 2, 3]);
        assert_eq!(of(9, 1, 10, true), vec![8, 9, 0]);
        assert_eq!(of(3, 3, 6, true), vec![0, 1, 2, 3, 4, 5]);
    }
}
