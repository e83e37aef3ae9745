//! The walls the engine bounces circles off (trading spin if they are rough): the arena's, at
//! an axis, and the segment walls inside it, at the point of the segment nearest the circle; and how the segment walls are
//! listed in the engine's cells.

use super::EventEngine;
use super::large::{large_circles, reach};
use crate::base::arena::Arena;
use crate::base::circle::CircleState;
use crate::base::collision_layers::{CollisionLayers, can_meet};
use crate::base::grid::Grid;
use crate::base::hits::{ArenaWall, Wall, WallHit};
use crate::base::segment::{Segment, SegmentCells};
use crate::collision::contact::combine_restitution;
use crate::step::boundary::put_back_inside;

impl EventEngine {
    pub(super) fn hit_wall(&mut self, i: usize, axis: usize) {
        if !self.arena.has_walls() {
            return;
        }
        self.advance_circle(i, self.now);
        let (min, max) = (self.arena.min, self.arena.max);
        let e = match self.own_restitution.as_slice() {
            [] => self.wall_restitution,
            own => combine_restitution(own[i], self.wall_restitution),
        };
        let bounce = self.contact_time_restitution(&[i], e);
        let scale = 1.0 + self.growth * self.now;
        let m = &mut self.motion[i];
        let (r, growth) = (m.radius * scale, m.radius * self.growth);
        let (lo, hi) = (min[axis] + r, max[axis] - r);
        let v = m.vel[axis];
        // Snap onto the wall (the event time puts it there up to rounding) and reflect, off a
        // wall that closes in at the rate the radius grows in a compression.
        // Which wall: the way it moves, or (at rest against a wall under gravity, or growing)
        // the nearer one.
        let high = if growth == 0.0 && v != 0.0 {
            v > 0.0
        } else {
            hi - m.pos[axis] < m.pos[axis] - lo
        };
        m.pos[axis] = if high { hi } else { lo };
        let wall_v = if high { -growth } else { growth };
        let new_v = wall_v - bounce * (v - wall_v);
        m.vel[axis] = new_v;
        let centre = m.pos;
        let mut normal = bevy::math::DVec2::ZERO;
        normal[axis] = if high { 1.0 } else { -1.0 };
        self.rough_wall(i, normal);
        self.rest_on_support(i, normal, e);
        self.sleep_if_jammed(i, e);
        let impulse = self.count_wall_hit(i, (new_v - v).abs());
        if let Some(log) = &mut self.hits {
            let wall = ArenaWall::on_axis(axis, high);
            let (point, normal) = wall.contact(centre, &self.arena);
            log.walls.push(WallHit {
                circle: i as u32,
                wall: Wall::Arena(wall),
                point,
                normal,
                impulse,
                normal_speed: v.abs(),
                time: self.now,
                count: 1,
            });
        }
        self.counter[i] += 1;
        self.predict(i);
    }

    /// Counts a wall hit that changed circle `i`'s velocity by `speed_change`, and returns the
    /// momentum the wall took up (infinite for an immovable circle, which is not added up).
    fn count_wall_hit(&mut self, i: usize, speed_change: f64) -> f64 {
        let impulse = if self.inv_mass[i] > 0.0 {
            speed_change / self.inv_mass[i]
        } else {
            f64::INFINITY
        };
        if impulse.is_finite() {
            self.stats.wall_impulse += impulse;
        }
        self.stats.wall_collisions += 1;
        impulse
    }

    pub(super) fn hit_segment(&mut self, i: usize, k: usize) {
        self.advance_circle(i, self.now);
        let e = match self.own_restitution.as_slice() {
            [] => self.wall_restitution,
            own => combine_restitution(own[i], self.wall_restitution),
        };
        let bounce = self.contact_time_restitution(&[i], e);
        let (segment, arena) = (self.segments[k], self.arena);
        let m = &mut self.motion[i];
        let (point, out, _) = segment.contact(m.pos, m.vel);
        let vn = m.vel.dot(out);
        let mut put_back = false;
        if vn < 0.0 {
            // Snap to touching (the event time puts it there up to rounding) and reflect.
            m.pos = point + out * m.radius;
            if arena.has_walls() && !arena.contains(m.pos) {
                // Only from a state no run reaches (a circle that began deep in both a segment
                // wall and an arena wall: a changed solver, wall or checkpoint): the snap would
                // put its centre past the arena wall. It is put back inside, as the discrete
                // solvers put back a centre a push-out moved past a wall.
                put_back_inside(&mut m.pos, m.radius, &arena);
                put_back = true;
            }
            let before = m.vel;
            m.vel -= out * ((1.0 + bounce) * vn);
            let speed_change = (m.vel - before).length();
            let impulse = self.count_wall_hit(i, speed_change);
            if let Some(log) = &mut self.hits {
                log.walls.push(WallHit {
                    circle: i as u32,
                    wall: Wall::Segment(k as u32),
                    point,
                    normal: -out,
                    impulse,
                    normal_speed: -vn,
                    time: self.now,
                    count: 1,
                });
            }
        }
        if put_back {
            self.relist(i);
        }
        if vn < 0.0 {
            self.rough_wall(i, -out);
        }
        // Pressed against the wall by gravity with no speed, or bounced off it weakly: rest.
        self.rest_on_support(i, -out, e);
        self.sleep_if_jammed(i, e);
        self.counter[i] += 1;
        self.predict(i);
    }
}

/// Where the engine keeps its circles and walls: the grid, the segment walls (none on a periodic
/// arena) and the cells they pass near, and the circles too large for the cells with how far
/// each reaches.
pub(super) struct Layout {
    pub(super) grid: Grid,
    pub(super) segments: Vec<Segment>,
    pub(super) segment_cells: SegmentCells,
    pub(super) large: Vec<u32>,
    pub(super) reach: Vec<u32>,
    /// Whether predictions must look at every image in reach ([`images_wrap`]).
    pub(super) images_wrap: bool,
}

/// The engine's [`Layout`]: cells at least `width` wide, and one diameter of every circle in
/// them (all but a few [`large_circles`] far wider than `width`), about four per circle or
/// segment at most; segment walls listed in the cells they pass within a largest radius of.
pub(super) fn walls_inside(
    arena: &Arena,
    circles: &[CircleState],
    segments: &[Segment],
    width: f64,
    layers: &[CollisionLayers],
) -> Layout {
    let segments = if arena.is_periodic() {
        &[][..]
    } else {
        segments
    };
    let largest = circles.iter().map(|c| c.radius).fold(0.0f64, f64::max);
    let (large, in_cells) = large_circles(circles, width, layers);
    let cap = circles.len() + segments.len();
    let grid = Grid::tiling(
        arena.min,
        arena.size(),
        width.max(2.0 * in_cells),
        cap,
        arena.is_periodic(),
    );
    // A little more than the largest radius, so a centre on a cell's edge by rounding still
    // finds the walls it touches.
    let margin = largest + 1e-9 * grid.cell.max_element();
    let segment_cells = SegmentCells::build(segments, grid, margin);
    let reach: Vec<u32> = large
        .iter()
        .map(|&i| reach(&grid, circles[i as usize].radius, in_cells))
        .collect();
    let images_wrap = images_wrap(&grid, &reach);
    Layout {
        grid,
        segments: segments.to_vec(),
        segment_cells,
        large,
        reach,
        images_wrap,
    }
}

/// Whether a pair may come to meet through another image than the one it is nearest in
/// without either circle crossing a cell edge first: on a periodic `grid` of fewer than four
/// cells a side (circles wider than a quarter of the box), or where a large circle's
/// neighbourhood (`reach` cells) wraps around the box.
fn images_wrap(grid: &Grid, reach: &[u32]) -> bool {
    let fewest = grid.cols.min(grid.rows) as u32;
    grid.periodic && (fewest < 4 || reach.iter().any(|&reach| 2 * reach + 3 > fewest))
}

/// What a cell crossing costs (moving between cell lists, one more event in the queue) and what
/// a collision's look at the 3×3 block of cells weighs, in pair predictions: fitted so that
/// [`cell_width`] picks what measured fastest on a dilute gas (`p2000.txt`: about 1.6 mean
/// spacings) and at area fraction 0.3 (about one diameter).
const CROSSING_COST: f64 = 26.0;
const COLLISION_WEIGHT: f64 = 60.0;

/// The cell width that makes a circle's travel cheapest, before the largest diameter is taken
/// into account. Per unit of path a circle crosses about `4 / (πL)` cells of width `L`, each
/// crossing followed by a look into three new cells, and collides about `√2 ρ d g` times, each
/// collision followed by a look into nine cells, with `ρ` circles per unit area of mean
/// diameter `d` and `g` Henderson's contact value. With `L = u·s`, `s = 1/√ρ` the mean spacing,
/// the cost is least where `CROSSING_COST / u² = 3 + COLLISION_WEIGHT · g · (d/s) · u`, solved
/// here by bisection. Dense gases get cells about a diameter wide; dilute ones, cells a few
/// spacings wide, so that a circle crosses fewer of them between collisions. Only the circles
/// that [`can_meet`] another under `layers` count: a sensor meets none, so nothing ever looks
/// for it in the cells.
pub(super) fn cell_width(
    arena: &Arena,
    circles: &[CircleState],
    layers: &[CollisionLayers],
) -> f64 {
    let radii = || {
        (0..circles.len())
            .filter(|&i| can_meet(layers, i))
            .map(|i| circles[i].radius)
    };
    let n = radii().count().max(1) as f64;
    let size = arena.size();
    let area = size.x * size.y;
    let spacing = (area / n).sqrt();
    let diameter = 2.0 * radii().sum::<f64>() / n;
    let fraction = arena.area_fraction(radii());
    let phi = fraction.min(0.8);
    let contact = (1.0 - 7.0 * phi / 16.0) / ((1.0 - phi) * (1.0 - phi));
    let collisions = COLLISION_WEIGHT * contact * diameter / spacing;
    // Falls from +∞ near 0 to below 0 at √(CROSSING_COST / 3).
    let excess = |u: f64| CROSSING_COST / (u * u) - 3.0 - collisions * u;
    let (mut lo, mut hi) = (0.0, (CROSSING_COST / 3.0).sqrt());
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    // At least four cells a side, so that a pair in neighbouring cells is nearest through
    // one image of a periodic arena.
    (hi * spacing).min(0.25 * size.min_element())
}

#[cfg(test)]
mod tests {
    use bevy::math::DVec2;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::base::arena::Boundary;

    /// A gas of `n` circles of radius `r` on a jittered lattice, with pseudo-random velocities.
    fn gas(n: usize, r: f64, arena: &Arena) -> Vec<CircleState> {
        let side = (n as f64).sqrt().ceil() as usize;
        let step = arena.size() / side as f64;
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut next = || rng.random_range(-0.5..0.5);
        (0..n)
            .map(|k| {
                let cell = DVec2::new((k % side) as f64 + 0.5, (k / side) as f64 + 0.5);
                let jitter = DVec2::new(next(), next()) * (step - 2.0 * r * DVec2::ONE) * 0.9;
                let velocity = DVec2::new(next(), next());
                CircleState::new(arena.min + cell * step + jitter, velocity, r)
            })
            .collect()
    }

    #[test]
    fn the_cells_do_not_change_the_trajectories() {
        // Only collisions and wall hits move a circle's reference point, and every time is
        // worked out from reference points: any grid gives the same run, bit for bit.
        for boundary in [Boundary::Walls, Boundary::Periodic] {
            let arena = Arena::unit_square(boundary);
            let circles = gas(400, 0.01, &arena);
            let run = |width: f64| {
                let mut engine = EventEngine::with_cells(&circles, &arena, &[], (1.0, 1.0), width);
                let cols = engine.grid.cols;
                for step in 1..=20 {
                    engine.advance_to(0.1 * step as f64, u64::MAX).unwrap();
                }
                let state: Vec<_> = (0..engine.len())
                    .map(|i| (engine.position(i), engine.velocity(i)))
                    .collect();
                (cols, engine.stats().pair_collisions, state)
            };
            let (fine, coarse) = (run(0.0), run(0.2));
            assert_eq!(
                (fine.0, coarse.0),
                (40, 5),
                "{boundary:?}: the grids differ"
            );
            assert!(fine.1 > 1000, "{boundary:?}: only {} collisions", fine.1);
            assert_eq!(fine.1, coarse.1, "{boundary:?}: collision counts");
            assert!(fine.2 == coarse.2, "{boundary:?}: the states differ");
        }
    }

    #[test]
    fn dense_gases_get_cells_a_diameter_wide_dilute_ones_wider() {
        let arena = Arena::unit_square(Boundary::Periodic);
        let dense = gas(2500, 0.009, &arena); // area fraction 0.64
        assert!(cell_width(&arena, &dense, &[]) < 2.0 * 0.009);
        let dilute = gas(2000, 0.001, &arena); // 0.006, like p2000.txt
        let spacing = (1.0f64 / 2000.0).sqrt();
        let width = cell_width(&arena, &dilute, &[]);
        assert!((1.2 * spacing..2.0 * spacing).contains(&width), "{width}");
    }

    #[test]
    fn a_circle_wedged_between_a_segment_and_a_wall_stays_inside() {
        // A large circle begun deep in a segment wall and the floor at once (a state from the
        // checkpoint fuzz target): the snap to touching the segment lands its centre below the
        // floor, and it must be put back inside.
        let arena = Arena::centered(DVec2::splat(4.0));
        let segments = [
            Segment::new(DVec2::new(-2.0, -1.0188), DVec2::new(0.0, 0.0)),
            Segment::new(DVec2::new(0.0, -1.35), DVec2::new(2.0, -1.2)),
        ];
        let circle = CircleState::new(DVec2::new(-0.3, -0.9), DVec2::new(0.0, 0.5), 1.92);
        let mut engine = EventEngine::new(&[circle], &arena, &segments, 0.5, 0.6);
        for step in 1..=10 {
            let _ = engine.advance_to(f64::from(step) / 60.0, 100_000);
            let at = engine.position(0);
            assert!(
                arena.contains(at),
                "step {step}: the centre left the arena, at {at}"
            );
        }
        assert!(engine.stats().wall_collisions > 0, "it met the segment");
    }
}
