//! The arena's edges: [`WallsPlugin`], walls with the seed's reflection rule in vector form
//! ([`reflect_off_walls`], a plain function), or [`PeriodicPlugin`], wrap-around; and the
//! segment walls inside the arena ([`segments`]), with the same rule. All in
//! [`CircleSystems::Boundary`] of the discrete solvers. Wall hits are counted here
//! ([`WallCollisions`]), by whichever solver makes them, and written as
//! [`WallHit`] messages when the scene asks for them.
//!
//! Per axis: a circle whose edge is past a wall and that moves outward is mirrored back inside
//! and its normal velocity flipped; one that is past a wall but already moving inward (pushed
//! there by a collision) is only put back, so it cannot be flipped twice and stick to the wall.

use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::components::{Position, SolverCircles};
use crate::base::config::Effects;
use crate::base::hits::{ArenaWall, HitLog, Wall, WallHit};
use crate::collision::contact::combine_restitution;
use crate::step::effects::{Effect, register_effect};
use crate::step::schedule::{CircleStep, CircleSystems, StepDt, SubstepStart};

pub mod segments;

pub use segments::SegmentsPlugin;

/// Keeps every circle inside the [`Arena`] by reflecting it off the walls, when the arena has
/// walls, under `discrete` and `substeps=N`. (`soft`, `swept` and `exact` hit the walls inside
/// their own step, whether or not this plugin is in: an arena without walls is
/// [`Boundary::Open`](crate::base::arena::Boundary::Open).)
#[derive(Clone, Copy, Debug, Default)]
pub struct WallsPlugin;

impl Plugin for WallsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<WallCollisions>()
            .add_message::<WallHit>();
        register_effect(app, Effect::Walls, &[CircleStep.intern()], || {
            bounce_off_walls
                .in_set(CircleSystems::Boundary)
                .into_configs()
        });
    }
}

/// Wraps circles leaving one side of a periodic [`Arena`] in at the opposite one.
#[derive(Clone, Copy, Debug, Default)]
pub struct PeriodicPlugin;

impl Plugin for PeriodicPlugin {
    fn build(&self, app: &mut App) {
        register_effect(app, Effect::Periodic, &[CircleStep.intern()], || {
            wrap_around.in_set(CircleSystems::Boundary).into_configs()
        });
    }
}

/// Wall hits since the last (re)spawn, under any solver.
#[derive(
    Resource, Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize,
)]
pub struct WallCollisions {
    /// Wall reflections.
    pub count: u64,
    /// Momentum the walls took up, `Σ m |Δv|` (for the wall pressure).
    pub impulse: f64,
}

/// Wraps every circle's centre back into the arena.
fn wrap_around(arena: Res<Arena>, mut circles: Query<&mut Position>) {
    let arena = *arena;
    circles.par_iter_mut().for_each(|mut p| {
        if !arena.contains(p.0) || p.0.cmpeq(arena.max).any() {
            p.0 = arena.wrap(p.0);
        }
    });
}

/// Reflects one circle off the walls of `arena`, scaling the normal velocity by `restitution`
/// at each hit; returns how many wall hits that took.
///
/// A circle that overshot by several arena widths in one step (a huge speed or `dt`) is folded
/// back exactly as if it had bounced each time, so it always ends inside. A circle wider than
/// the arena on an axis is centred on that axis and its velocity there zeroed: it cannot move.
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::base::arena::{Arena, Boundary};
/// use moving_circles::step::boundary::reflect_off_walls;
///
/// let unit = Arena::unit_square(Boundary::Walls);
/// // 0.15 past the right wall (centre at most 0.9 with radius 0.1), moving out.
/// let (mut p, mut v) = (DVec2::new(1.05, 0.5), DVec2::new(1.0, 0.0));
/// assert_eq!(reflect_off_walls(&mut p, &mut v, 0.1, &unit, 1.0), 1);
/// assert!((p.x - 0.75).abs() < 1e-12 && v.x == -1.0);
/// ```
pub fn reflect_off_walls(
    position: &mut DVec2,
    velocity: &mut DVec2,
    radius: f64,
    arena: &Arena,
    restitution: f64,
) -> u64 {
    let [x, y] = reflect_off_walls_per_axis(position, velocity, radius, arena, restitution);
    x.saturating_add(y)
}

/// Mirrors a centre past a wall back inside `arena` as a bounce would, leaving any velocity
/// alone: what a solver does with a centre that something other than motion (a push-out) put
/// outside.
pub(crate) fn put_back_inside(position: &mut DVec2, radius: f64, arena: &Arena) {
    let mut at_rest = DVec2::ZERO;
    reflect_off_walls(position, &mut at_rest, radius, arena, 1.0);
}

/// [`reflect_off_walls`], with the hits on the x walls and on the y walls apart.
pub fn reflect_off_walls_per_axis(
    position: &mut DVec2,
    velocity: &mut DVec2,
    radius: f64,
    arena: &Arena,
    restitution: f64,
) -> [u64; 2] {
    let mut hits = [0; 2];
    for (axis, hits) in hits.iter_mut().enumerate() {
        let lo = arena.min[axis] + radius;
        let hi = arena.max[axis] - radius;
        let n = reflect_axis(&mut position[axis], &mut velocity[axis], lo, hi);
        if n > 0 && restitution != 1.0 {
            // Past 2³¹ bounces any restitution below 1 has long rounded the speed to zero.
            velocity[axis] *= restitution.powi(n.min(i32::MAX as u64) as i32);
        }
        *hits = n;
    }
    hits
}

fn reflect_axis(p: &mut f64, v: &mut f64, lo: f64, hi: f64) -> u64 {
    if *p >= lo && *p <= hi {
        return 0;
    }
    let span = hi - lo;
    if span <= 0.0 {
        *p = 0.5 * (lo + hi);
        *v = 0.0;
        return 0;
    }
    let moving_out = (*p < lo && *v < 0.0) || (*p > hi && *v > 0.0);
    if !moving_out {
        *p = p.clamp(lo, hi);
        return 0;
    }
    // Unfold the motion onto a line of mirrored copies of [lo, hi]: the distance past `lo`
    // modulo two spans says where the circle is and which way it now moves.
    let unfolded = *p - lo;
    let period = 2.0 * span;
    let m = unfolded.rem_euclid(period);
    let spans = unfolded / span;
    let crossings = if spans < 0.0 {
        (-spans).ceil()
    } else {
        spans.floor()
    } as u64;
    let (folded, flipped) = if m <= span {
        (m, false)
    } else {
        (period - m, true)
    };
    // rem_euclid can round up to `period`; clamp keeps the result inside even then.
    *p = (lo + folded).clamp(lo, hi);
    if flipped {
        *v = -*v;
    }
    crossings.max(1)
}

/// Applies [`reflect_off_walls`] to every circle (with its own restitution combined with the
/// walls', if it has one), counts the hits and adds the momentum the walls took up
/// (`Σ m |Δv|`, for the wall pressure); with `effects.hit_messages`, writes a [`WallHit`] per
/// wall hit.
fn bounce_off_walls(
    arena: Res<Arena>,
    effects: Res<Effects>,
    clock: (Res<StepDt>, Res<SubstepStart>),
    mut walls: ResMut<WallCollisions>,
    mut log: Local<(HitLog, Vec<Entity>)>,
    mut messages: MessageWriter<WallHit>,
    mut circles: SolverCircles,
) {
    let (log, entities) = &mut *log;
    let mut hits = 0u64;
    let mut impulse = 0.0f64;
    for (entity, mut position, mut velocity, radius, mass, own, sleep) in &mut circles {
        if sleep.asleep {
            continue;
        }
        let (mut p, mut v) = (position.0, velocity.0);
        let e = own.map_or(effects.wall_restitution, |own| {
            combine_restitution(own.0, effects.wall_restitution)
        });
        let per_axis = reflect_off_walls_per_axis(&mut p, &mut v, radius.0, &arena, e);
        let n = per_axis[0].saturating_add(per_axis[1]);
        if n > 0 || p != position.0 {
            if n > 0 && mass.0.is_finite() {
                impulse += mass.0 * (v - velocity.0).length();
            }
            if n > 0 && effects.hit_messages {
                let i = entities.len() as u32;
                entities.push(entity);
                let before = (position.0, velocity.0);
                record_wall_hits(log, i, before, (p, v), per_axis, (radius.0, mass.0), &arena);
            }
            position.0 = p;
            velocity.0 = v;
            hits = hits.saturating_add(n);
        }
    }
    walls.count = walls.count.saturating_add(hits);
    walls.impulse += impulse;
    if effects.hit_messages {
        let (dt, start) = clock;
        log.send_wall_hits(|i| entities[i as usize], start.0 + dt.0, &mut messages);
        entities.clear();
    }
}

/// Records the wall hits of circle `i` (of radius and mass `body`), which one reflection took
/// from state `before` to `after`, `per_axis` hits on each axis.
fn record_wall_hits(
    log: &mut HitLog,
    i: u32,
    before: (DVec2, DVec2),
    after: (DVec2, DVec2),
    per_axis: [u64; 2],
    body: (f64, f64),
    arena: &Arena,
) {
    let (radius, mass) = body;
    for (axis, &count) in per_axis.iter().enumerate() {
        if count == 0 {
            continue;
        }
        // The first wall is the one overshot; each further crossing hits the other one.
        let first_high = before.0[axis] > arena.max[axis] - radius;
        let wall = ArenaWall::on_axis(axis, first_high == (count % 2 == 1));
        let (point, normal) = wall.contact(after.0, arena);
        log.walls.push(WallHit {
            circle: i,
            wall: Wall::Arena(wall),
            point,
            normal,
            impulse: if mass.is_finite() {
                mass * (after.1[axis] - before.1[axis]).abs()
            } else {
                f64::INFINITY
            },
            normal_speed: before.1[axis].abs(),
            time: 0.0,
            count,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit() -> Arena {
        Arena::unit_square(crate::base::arena::Boundary::Walls)
    }

    #[test]
    fn overshoot_is_mirrored_and_velocity_flipped() {
        let (mut p, mut v) = (DVec2::new(1.05, 0.5), DVec2::new(1.0, 0.2));
        let hits = reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0);
        assert_eq!(hits, 1);
        assert!((p.x - 0.75).abs() < 1e-6, "{p}");
        assert_eq!(v, DVec2::new(-1.0, 0.2));
    }

    #[test]
    fn a_circle_already_moving_inward_is_put_back_not_flipped() {
        let (mut p, mut v) = (DVec2::new(0.05, 0.5), DVec2::new(0.3, 0.0));
        assert_eq!(reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0), 0);
        assert_eq!(p, DVec2::new(0.1, 0.5));
        assert_eq!(v, DVec2::new(0.3, 0.0));
    }

    #[test]
    fn many_arena_widths_in_one_step_fold_back_inside() {
        // lo = 0.1, hi = 0.9, span 0.8: 3.3 past lo is 4 wall hits (even: same direction)
        // and 0.1 into the fifth span.
        let (mut p, mut v) = (DVec2::new(3.4, 0.5), DVec2::new(5.0, 0.0));
        assert_eq!(reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0), 4);
        assert!((p.x - 0.2).abs() < 1e-5, "{p}");
        assert_eq!(v.x, 5.0);
        // 0.9 + 0.5 past hi: one hit, mirrored to 0.4, moving back.
        let (mut p, mut v) = (DVec2::new(1.4, 0.5), DVec2::new(5.0, 0.0));
        assert_eq!(reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0), 1);
        assert!((p.x - 0.4).abs() < 1e-5, "{p}");
        assert_eq!(v.x, -5.0);
        // Past the low wall, moving out: one hit.
        let (mut p, mut v) = (DVec2::new(-0.1, 0.5), DVec2::new(-5.0, 0.0));
        assert_eq!(reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0), 1);
        assert!((p.x - 0.3).abs() < 1e-5, "{p}");
        assert_eq!(v.x, 5.0);
        let (mut p, mut v) = (DVec2::new(-1e7, 0.5), DVec2::new(-1e9, 0.0));
        reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 1.0);
        assert!(unit().contains(p) && p.is_finite());
    }

    #[test]
    fn wall_restitution_scales_the_normal_velocity_per_hit() {
        let (mut p, mut v) = (DVec2::new(1.05, 0.5), DVec2::new(2.0, 1.0));
        reflect_off_walls(&mut p, &mut v, 0.1, &unit(), 0.5);
        assert_eq!(v, DVec2::new(-1.0, 1.0));
    }
}
