//! Segment walls under the discrete solvers: [`SegmentsPlugin`] schedules
//! `bounce_off_segments` when the scene has [`Segments`], and [`reflect_off_segment`] is its
//! kernel: the arena walls' rule, turned to the segment's normal at the point nearest the
//! circle (at an end, the normal points from the end to the centre).
//!
//! Like the arena walls, a step that carries a circle across a thin segment is not noticed: a
//! discrete step only sees where circles end. `swept` and `exact` hit segments at the exact time
//! of impact instead (`exact::toi::segment_time_of_impact`).

use bevy::ecs::schedule::ScheduleLabel;
use bevy::math::DVec2;
use bevy::prelude::*;

use super::WallCollisions;
use crate::base::arena::Arena;
use crate::base::components::SolverCircles;
use crate::base::config::Effects;
use crate::base::hits::{HitLog, Wall, WallHit};
use crate::base::segment::{Segment, SegmentCells, Segments};
use crate::collision::contact::combine_restitution;
use crate::step::effects::{Effect, EffectSystems, register_effect};
use crate::step::schedule::{CircleStep, CircleSystems, StepDt, SubstepStart};

/// Reflects circles off the scene's segment walls (before the arena walls, which then have the
/// last word on keeping every circle inside).
#[derive(Clone, Copy, Debug, Default)]
pub struct SegmentsPlugin;

impl Plugin for SegmentsPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Segments>()
            .init_resource::<WallCollisions>()
            .add_message::<WallHit>();
        register_effect(app, Effect::Segments, &[CircleStep.intern()], || {
            bounce_off_segments
                .in_set(CircleSystems::Boundary)
                .before(EffectSystems(Effect::Walls))
                .into_configs()
        });
    }
}

/// A circle's bounce off a segment wall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentBounce {
    /// The point of the segment nearest the circle's centre before the bounce.
    pub point: DVec2,
    /// Unit normal from the circle towards the segment.
    pub normal: DVec2,
    /// Speed at which the circle approached, before the bounce (positive).
    pub normal_speed: f64,
}

/// Reflects a circle of `radius` at `position` moving at `velocity` off `segment`, with the
/// arena walls' rule: if it overlaps the segment and moves into it, it is mirrored back out
/// along the normal at the nearest point and its normal velocity is reversed and scaled by
/// `restitution` (the bounce is returned); if it overlaps but already moves away, it is only put
/// back to touching. A centre exactly on the segment goes back the way it came.
///
/// `from` is where the centre was before the boundary pass began: a centre that another
/// segment's push carried across this segment's line (between its ends) is on the wrong side,
/// and is put back on the side it came from rather than pushed on through (so a circle in a
/// narrow V cannot be pushed out of it from one side to the other).
///
/// ```
/// use bevy::math::DVec2;
/// use moving_circles::step::boundary::segments::reflect_off_segment;
/// use moving_circles::base::segment::Segment;
///
/// let floor = Segment::new(DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0));
/// let (mut p, mut v) = (DVec2::new(0.0, 0.4), DVec2::new(1.0, -2.0));
/// let from = p;
/// let bounce = reflect_off_segment(&mut p, &mut v, 0.5, &floor, 1.0, from).unwrap();
/// assert_eq!(v, DVec2::new(1.0, 2.0)); // the seed's angle rule on a horizontal wall
/// assert!((p.y - 0.6).abs() < 1e-12 && bounce.normal == DVec2::new(0.0, -1.0));
/// ```
pub fn reflect_off_segment(
    position: &mut DVec2,
    velocity: &mut DVec2,
    radius: f64,
    segment: &Segment,
    restitution: f64,
    from: DVec2,
) -> Option<SegmentBounce> {
    let (point, mut out, mut distance) = segment.contact(*position, *velocity);
    let normal = segment.normal();
    let between_ends = point != segment.a && point != segment.b;
    let (before, now) = (
        (from - segment.a).dot(normal),
        (*position - segment.a).dot(normal),
    );
    if between_ends && before * now < 0.0 {
        // Pushed across the line this pass: back towards where it was, by the whole depth.
        out = normal * before.signum();
        distance = -now.abs();
    }
    if distance >= radius {
        return None;
    }
    let vn = velocity.dot(out);
    if vn >= 0.0 {
        *position = point + out * radius;
        return None;
    }
    *position += out * (2.0 * (radius - distance));
    *velocity -= out * ((1.0 + restitution) * vn);
    Some(SegmentBounce {
        point,
        normal: -out,
        normal_speed: -vn,
    })
}

/// Whether [`reflect_off_segment`] would leave a circle of `radius` at `position` (at `from`
/// when the boundary pass began) alone against `segment`, whose [`Segment::normal`] is
/// `normal`: clear of it and not carried across its line. Decided without the square root the
/// full test takes; `false` may also mean "too close to tell", and the full test decides.
#[inline]
fn clear_of(segment: &Segment, normal: DVec2, position: DVec2, radius: f64, from: DVec2) -> bool {
    let point = segment.closest_point(position);
    let between_ends = point != segment.a && point != segment.b;
    let (before, now) = (
        (from - segment.a).dot(normal),
        (position - segment.a).dot(normal),
    );
    let crossed = between_ends && before * now < 0.0;
    // A squared distance past the squared radius by more than rounding has a distance of at
    // least the radius, as the full test finds it.
    !crossed && (position - point).length_squared() > radius * radius * (1.0 + 1e-12)
}

/// Passes over the segments near a circle in one boundary pass.
pub const SEGMENT_PASSES: usize = 4;

/// Applies [`reflect_off_segment`] to every circle and each segment near it (with its own
/// restitution combined with the walls', if it has one), counts the bounces as wall hits and,
/// with `effects.hit_messages`, writes a [`WallHit`] per bounce.
#[allow(clippy::too_many_arguments)]
fn bounce_off_segments(
    arena: Res<Arena>,
    segments: Res<Segments>,
    effects: Res<Effects>,
    clock: (Res<StepDt>, Res<SubstepStart>),
    mut walls: ResMut<WallCollisions>,
    mut cells: Local<Option<(SegmentCells, Vec<DVec2>)>>,
    mut scratch: Local<(HitLog, Vec<Entity>, Vec<u32>)>,
    mut messages: MessageWriter<WallHit>,
    mut circles: SolverCircles,
) {
    if cells.is_none() || segments.is_changed() || arena.is_changed() {
        let normals = segments.0.iter().map(Segment::normal).collect();
        *cells = Some((SegmentCells::over_arena(&segments.0, &arena), normals));
    }
    let Some((cells, normals)) = cells.as_ref() else {
        return;
    };
    let (log, entities, near) = &mut *scratch;
    let (mut hits, mut impulse) = (0u64, 0.0f64);
    for (entity, mut position, mut velocity, radius, mass, own, sleep) in &mut circles {
        if sleep.asleep {
            continue;
        }
        near.clear();
        cells.near(position.0, radius.0, |k| near.push(k));
        if near.is_empty() {
            continue;
        }
        near.sort_unstable();
        near.dedup();
        let e = own.map_or(effects.wall_restitution, |own| {
            combine_restitution(own.0, effects.wall_restitution)
        });
        let (mut p, mut v) = (position.0, velocity.0);
        let from = p;
        // Each push may press the circle into another segment (a narrow V): a few passes
        // settle it, each bounce counted as a hit; a pass that changes nothing ends them.
        for _ in 0..SEGMENT_PASSES {
            let pass_start = (p, v);
            for &k in near.iter() {
                let segment = &segments.0[k as usize];
                if clear_of(segment, normals[k as usize], p, radius.0, from) {
                    continue;
                }
                let before = v;
                let Some(bounce) = reflect_off_segment(&mut p, &mut v, radius.0, segment, e, from)
                else {
                    continue;
                };
                hits += 1;
                let delta = mass.0 * (v - before).length();
                if delta.is_finite() {
                    impulse += delta;
                }
                if effects.hit_messages {
                    log.walls.push(WallHit {
                        circle: entities.len() as u32,
                        wall: Wall::Segment(k),
                        point: bounce.point,
                        normal: bounce.normal,
                        impulse: if mass.0.is_finite() {
                            delta
                        } else {
                            f64::INFINITY
                        },
                        normal_speed: bounce.normal_speed,
                        time: 0.0,
                        count: 1,
                    });
                    entities.push(entity);
                }
            }
            if (p, v) == pass_start {
                break;
            }
        }
        if p != position.0 {
            position.0 = p;
        }
        if v != velocity.0 {
            velocity.0 = v;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn floor() -> Segment {
        Segment::new(DVec2::new(-1.0, 0.0), DVec2::new(1.0, 0.0))
    }

    #[test]
    fn a_circle_found_clear_of_a_segment_is_one_the_full_test_leaves_alone() {
        use rand::{Rng, SeedableRng};
        // Circles around a tilted segment and a point, many of them just touching it (the
        // distance within rounding of the radius) and some carried across its line: whenever
        // the cheap test says clear, the full one moves nothing, and it says clear often.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let tilted = Segment::new(DVec2::new(-1.0, -0.3), DVec2::new(1.2, 0.4));
        let point = Segment::new(DVec2::new(0.5, 0.5), DVec2::new(0.5, 0.5));
        let mut clear = 0;
        for k in 0..200_000 {
            let segment = if k % 2 == 0 { tilted } else { point };
            let mut p = DVec2::new(rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0));
            let radius = match k % 3 {
                // Exactly as far as the segment: on the edge of touching.
                0 => segment.distance(p),
                _ => rng.random_range(0.01..1.0),
            };
            let from = match k % 5 {
                0 => p + DVec2::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)),
                _ => p,
            };
            let mut v = DVec2::new(rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
            if !clear_of(&segment, segment.normal(), p, radius, from) {
                continue;
            }
            clear += 1;
            let (p0, v0) = (p, v);
            let bounce = reflect_off_segment(&mut p, &mut v, radius, &segment, 0.5, from);
            assert_eq!(
                (bounce, p, v),
                (None, p0, v0),
                "{segment:?}, {p0}, r {radius}"
            );
        }
        assert!(clear > 50_000, "only {clear} found clear");
    }

    #[test]
    fn an_end_reflects_along_the_line_from_it_to_the_centre() {
        // Head on into the right end along the segment's line.
        let (mut p, mut v) = (DVec2::new(1.4, 0.0), DVec2::new(-2.0, 0.0));
        let from = p;
        let bounce = reflect_off_segment(&mut p, &mut v, 0.5, &floor(), 1.0, from).unwrap();
        assert_eq!(v, DVec2::new(2.0, 0.0));
        assert!((p.x - 1.6).abs() < 1e-12, "{p}");
        assert_eq!((bounce.point, bounce.normal), (DVec2::X, -DVec2::X));
    }

    #[test]
    fn a_circle_moving_away_is_only_put_back() {
        let (mut p, mut v) = (DVec2::new(0.0, -0.3), DVec2::new(0.0, -1.0));
        let from = p;
        assert_eq!(
            reflect_off_segment(&mut p, &mut v, 0.5, &floor(), 1.0, from),
            None
        );
        assert_eq!((p, v), (DVec2::new(0.0, -0.5), DVec2::new(0.0, -1.0)));
    }

    #[test]
    fn a_centre_on_the_segment_goes_back_the_way_it_came() {
        let (mut p, mut v) = (DVec2::ZERO, DVec2::new(0.0, 3.0));
        let from = p;
        reflect_off_segment(&mut p, &mut v, 0.5, &floor(), 0.5, from).unwrap();
        assert_eq!(v, DVec2::new(0.0, -1.5));
        assert_eq!(p, DVec2::new(0.0, -1.0));
    }
}
