//! The walls the engine bounces circles off: the arena's, at an axis, and the segment walls
//! inside it, at the point of the segment nearest the circle; and how the segment walls are
//! listed in the engine's cells.

use super::EventEngine;
use crate::arena::Arena;
use crate::circle::CircleState;
use crate::collide::contact::combine_restitution;
use crate::grid::Grid;
use crate::hits::{ArenaWall, Wall, WallHit};
use crate::segment::{Segment, SegmentCells};

impl EventEngine {
    pub(super) fn hit_wall(&mut self, i: usize, axis: usize) {
        if self.arena.is_periodic() {
            return;
        }
        self.advance_circle(i, self.now);
        let (min, max) = (self.arena.min, self.arena.max);
        let e = match self.own_restitution.as_slice() {
            [] => self.wall_restitution,
            own => combine_restitution(own[i], self.wall_restitution),
        };
        let m = &mut self.motion[i];
        let (lo, hi) = (min[axis] + m.radius, max[axis] - m.radius);
        let v = m.vel[axis];
        // Snap onto the wall (the event time puts it there up to rounding) and reflect.
        let high = v > 0.0;
        m.pos[axis] = if high { hi } else { lo };
        let new_v = -e * v;
        m.vel[axis] = new_v;
        let centre = m.pos;
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
        let segment = self.segments[k];
        let m = &mut self.motion[i];
        let (point, out, _) = segment.contact(m.pos, m.vel);
        let vn = m.vel.dot(out);
        if vn < 0.0 {
            // Snap to touching (the event time puts it there up to rounding) and reflect.
            m.pos = point + out * m.radius;
            let before = m.vel;
            m.vel -= out * ((1.0 + e) * vn);
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
        self.counter[i] += 1;
        self.predict(i);
    }
}

/// The engine's grid (cells at least one largest diameter wide, about four per circle or
/// segment at most) and the segment walls it keeps, listed in the cells they pass within a
/// largest radius of (none on a periodic arena).
pub(super) fn walls_inside(
    arena: &Arena,
    circles: &[CircleState],
    segments: &[Segment],
) -> (Grid, Vec<Segment>, SegmentCells) {
    let segments = if arena.is_periodic() {
        &[][..]
    } else {
        segments
    };
    let largest = circles.iter().map(|c| c.radius).fold(0.0f64, f64::max);
    let cap = circles.len() + segments.len();
    let grid = Grid::tiling(
        arena.min,
        arena.size(),
        2.0 * largest,
        cap,
        arena.is_periodic(),
    );
    // A little more than the largest radius, so a centre on a cell's edge by rounding still
    // finds the walls it touches.
    let margin = largest + 1e-9 * grid.cell.max_element();
    let cells = SegmentCells::build(segments, grid, margin);
    (grid, segments.to_vec(), cells)
}
