//! Spatial queries for game code: what is at a point, what overlaps a circle, what a ray or a
//! moving circle meets first, against circles, the arena's walls and segment walls, through
//! the [`SpatialQuery`] system parameter.
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! fn aim(query: SpatialQuery) -> Option<CastHit> {
//!     // The first thing a ray from the origin to the right meets, circles or walls.
//!     query.ray_cast(DVec2::ZERO, DVec2::X, f64::INFINITY, &QueryFilter::default())
//! }
//!
//! let mut app = moving_circles::tools::run::headless_app(CirclesConfig::default());
//! let target = app.world_mut().spawn((Radius(0.5), Position(DVec2::new(3.0, 0.0)))).id();
//! app.update(); // a step: the index sees the circles as they are after it
//! let hit = app.world_mut().run_system_cached(aim).unwrap().unwrap();
//! assert_eq!(hit.target, Target::Circle(target));
//! assert_eq!((hit.distance, hit.point, hit.normal), (2.5, DVec2::new(2.5, 0.0), -DVec2::X));
//! ```
//!
//! The queries run on an index of the circles ([`index::CircleIndex`], the broad phase's cell
//! lists) built by the first query after each fixed step, from the circles as they are then,
//! and shared by every system until the next step: a query costs about what the few cells it
//! looks at hold (a point among a million circles well under a microsecond), and a scene that
//! asks nothing pays nothing. Circles spawned, moved or despawned by game code after that
//! build are seen from the next step on, or at once after [`SpatialQuery::refresh`]. Segment
//! walls are tested one by one (a scene has at most
//! [`MAX_SEGMENTS`](crate::base::segment::MAX_SEGMENTS)). Walls are the arena's four edges when
//! it has walls, and every segment wall. Shapes are solid: a ray that starts inside a circle
//! meets it at distance 0. On a periodic arena queries use the minimum image and casts wrap
//! through the seams, for at most [`PERIODIC_REACH`](index::PERIODIC_REACH) box diagonals.
//! `tests/suite/queries.rs` checks the index against brute force on 10,000 random scenes
//! (narrow and decade-wide radii, walled, open and periodic arenas) and `SpatialQuery`, walls
//! and segments included, on 10,000 more queries.

pub mod index;
pub mod shapes;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{PoisonError, RwLock};

use bevy::ecs::entity::EntityHashSet;
use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::arena::Arena;
use crate::base::collision_layers::{CollisionLayers, Sensor};
use crate::base::components::{Position, Radius};
use crate::base::hits::{ArenaWall, Wall};
use crate::base::segment::{Segment, Segments};
use index::CircleIndex;
use shapes::{disc_contact, ray_capsule, segment_contact};

/// Adds the [`SpatialIndex`] that [`SpatialQuery`] reads, marked out of date after every
/// fixed step (part of [`CirclesPlugins`](crate::CirclesPlugins)).
#[derive(Clone, Copy, Debug, Default)]
pub struct SpatialQueryPlugin;

impl Plugin for SpatialQueryPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<SpatialIndex>()
            .add_systems(FixedLast, |index: Res<SpatialIndex>| index.mark_stale());
    }
}

/// What a query found: a circle, or a wall (an edge of the arena or a segment wall).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Target {
    /// A circle entity.
    Circle(Entity),
    /// An arena wall or a segment wall.
    Wall(Wall),
}

/// Where a ray or a moving circle first meets something.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CastHit {
    /// What it met.
    pub target: Target,
    /// How far it travelled first (0 if it started inside or overlapping).
    pub distance: f64,
    /// Where: for a ray, its point at `distance`; for a moving circle, the point of the target
    /// it touches.
    pub point: DVec2,
    /// Unit normal of the target's surface there, pointing out of the target towards the ray
    /// or the circle's centre.
    pub normal: DVec2,
}

/// Which circles and walls a query considers: circles only, walls only, all but given
/// entities (the caster), without sensors, or only the circles of some layers.
///
/// ```
/// use bevy::math::DVec2;
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// #[derive(Component)]
/// struct Player;
///
/// /// What the player would hit shooting to the right, itself left out.
/// fn shoot(player: Query<(Entity, &Position), With<Player>>, query: SpatialQuery) {
///     for (me, at) in &player {
///         let filter = QueryFilter::default().excluding([me]);
///         if let Some(hit) = query.ray_cast(at.0, DVec2::X, 20.0, &filter) {
///             info!("{:?} at {} m, normal {}", hit.target, hit.distance, hit.normal);
///         }
///     }
/// }
/// # bevy::ecs::system::assert_is_system(shoot);
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct QueryFilter {
    /// Whether circles count.
    pub circles: bool,
    /// Whether the arena's walls and the segment walls count.
    pub walls: bool,
    /// Circles left out (the caster itself, say).
    pub excluded: EntityHashSet,
    /// The groups a circle must be in (one of them) to count, as
    /// [`CollisionLayers::memberships`] (a circle without layers is in group 0).
    pub mask: u32,
    /// Whether [`Sensor`] circles count.
    pub sensors: bool,
}

impl Default for QueryFilter {
    fn default() -> Self {
        Self {
            circles: true,
            walls: true,
            excluded: EntityHashSet::default(),
            mask: u32::MAX,
            sensors: true,
        }
    }
}

impl QueryFilter {
    /// Circles only, no walls.
    pub fn circles_only() -> Self {
        Self {
            walls: false,
            ..default()
        }
    }

    /// Walls only, no circles.
    pub fn walls_only() -> Self {
        Self {
            circles: false,
            ..default()
        }
    }

    /// This filter, leaving out `entities` too.
    pub fn excluding(mut self, entities: impl IntoIterator<Item = Entity>) -> Self {
        self.excluded.extend(entities);
        self
    }

    /// This filter, counting only circles in one of the groups of `mask`.
    pub fn with_mask(self, mask: u32) -> Self {
        Self { mask, ..self }
    }

    /// This filter, leaving sensors out (a ray that should see only what pushes back).
    pub fn excluding_sensors(self) -> Self {
        Self {
            sensors: false,
            ..self
        }
    }

    fn takes(&self, entity: Entity, (memberships, sensor): (u32, bool)) -> bool {
        self.circles
            && memberships & self.mask != 0
            && (self.sensors || !sensor)
            && !self.excluded.contains(&entity)
    }
}

/// The circle index the queries share, rebuilt on the first query after it goes out of date.
#[derive(Resource, Debug)]
pub struct SpatialIndex {
    built: RwLock<Built>,
    stale: AtomicBool,
}

#[derive(Debug, Default)]
struct Built {
    circles: CircleIndex,
    entities: Vec<Entity>,
    /// Each circle's memberships and whether it is a sensor.
    kinds: Vec<(u32, bool)>,
    /// The arena the index was built for.
    arena: Arena,
    /// Centres and radii while building, reused.
    scratch: Vec<(DVec2, f64)>,
}

impl Built {
    /// Whether `filter` takes circle `i` of the index.
    fn takes(&self, filter: &QueryFilter, i: u32) -> bool {
        let i = i as usize;
        filter.takes(self.entities[i], self.kinds[i])
    }
}

impl Default for SpatialIndex {
    fn default() -> Self {
        Self {
            built: RwLock::default(),
            stale: AtomicBool::new(true),
        }
    }
}

impl SpatialIndex {
    /// Marks the index out of date: the next query rebuilds it.
    pub fn mark_stale(&self) {
        self.stale.store(true, Ordering::Release);
    }
}

/// What the index holds of each circle.
type Indexed = (
    Entity,
    &'static Position,
    &'static Radius,
    Option<&'static CollisionLayers>,
    Has<Sensor>,
);

/// Spatial queries against the circles, the arena's walls and the segment walls, as a system
/// parameter (see the [module](self) for when the index sees a change). Directions need not be
/// unit length; a zero or non-finite direction, a negative or NaN radius or distance, or a
/// non-finite point finds nothing.
#[derive(SystemParam)]
pub struct SpatialQuery<'w, 's> {
    circles: Query<'w, 's, Indexed>,
    index: Res<'w, SpatialIndex>,
    arena: Res<'w, Arena>,
    segments: Res<'w, Segments>,
}

impl SpatialQuery<'_, '_> {
    /// Rebuilds the index from the circles as they are now, for a system that moved or spawned
    /// circles since the last step and queries them at once.
    pub fn refresh(&self) {
        self.index.mark_stale();
    }

    /// The circles that contain `point` (on the rim counts), in the index's order.
    pub fn point(&self, point: DVec2, filter: &QueryFilter) -> Vec<Entity> {
        self.near(point, 0.0, filter, |offset, r| {
            offset.length_squared() <= r * r
        })
    }

    /// Everything a circle of `radius` at `centre` overlaps: the circles whose centres are
    /// nearer than the sum of the radii (as the solvers count an overlap), in the index's
    /// order, then the walls nearer than `radius` to `centre`.
    pub fn overlap_circle(&self, centre: DVec2, radius: f64, filter: &QueryFilter) -> Vec<Target> {
        if radius.is_nan() || radius < 0.0 {
            return Vec::new();
        }
        let circles = self.near(centre, radius, filter, |offset, r| {
            offset.length() < r + radius
        });
        let mut found: Vec<Target> = circles.into_iter().map(Target::Circle).collect();
        if filter.walls && centre.is_finite() {
            found.extend(
                self.walls()
                    .filter(|(_, s)| s.distance(centre) < radius)
                    .map(|(wall, _)| Target::Wall(wall)),
            );
        }
        found
    }

    /// The first circle or wall a ray from `origin` along `direction` meets within
    /// `max_distance` (`f64::INFINITY` for no limit).
    pub fn ray_cast(
        &self,
        origin: DVec2,
        direction: DVec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<CastHit> {
        self.circle_cast(origin, 0.0, direction, max_distance, filter)
    }

    /// The first circle or wall that a circle of `radius` moving from `centre` along
    /// `direction` touches within `max_distance`; a circle at a tie, the lower-numbered wall
    /// (the arena's, then segments in order) among walls.
    pub fn circle_cast(
        &self,
        centre: DVec2,
        radius: f64,
        direction: DVec2,
        max_distance: f64,
        filter: &QueryFilter,
    ) -> Option<CastHit> {
        let d = direction.try_normalize()?;
        if !(centre.is_finite() && radius >= 0.0 && max_distance >= 0.0) {
            return None;
        }
        let circle = filter.circles.then(|| {
            self.with_index(|built| {
                let takes = |i: u32| built.takes(filter, i);
                let hit = built.circles.cast(centre, d, radius, max_distance, takes)?;
                Some((
                    hit.distance,
                    Target::Circle(built.entities[hit.index as usize]),
                    hit,
                ))
            })
        });
        let wall = filter.walls.then(|| {
            self.walls()
                .filter_map(|(wall, s)| Some((ray_capsule(centre, d, &s, radius)?, wall, s)))
                .filter(|hit| hit.0 <= max_distance)
                .min_by(|a, b| a.0.total_cmp(&b.0))
        });
        let at = |t: f64| centre + d * t;
        let hit = match (circle.flatten(), wall.flatten()) {
            (Some((t, target, c)), w) if w.is_none_or(|w| t <= w.0) => {
                let (point, normal) = disc_contact(at(t), d, c.centre, c.radius);
                (t, target, point, normal)
            }
            (_, Some((t, wall, s))) => {
                let (point, normal) = segment_contact(at(t), d, &s);
                (t, Target::Wall(wall), point, normal)
            }
            (_, None) => return None,
        };
        let (distance, target, contact, normal) = hit;
        let point = if radius == 0.0 { at(distance) } else { contact };
        Some(CastHit {
            target,
            distance,
            point,
            normal,
        })
    }

    /// The circles `hits(offset, radius)` takes among those the index finds within `reach`
    /// of `p`, in index order.
    fn near(
        &self,
        p: DVec2,
        reach: f64,
        filter: &QueryFilter,
        hits: impl Fn(DVec2, f64) -> bool,
    ) -> Vec<Entity> {
        if !filter.circles {
            return Vec::new();
        }
        self.with_index(|built| {
            let mut found = Vec::new();
            built.circles.for_each_near(p, reach, |i, offset, r| {
                if hits(offset, r) && built.takes(filter, i) {
                    found.push(i);
                }
            });
            found.sort_unstable();
            found
                .into_iter()
                .map(|i| built.entities[i as usize])
                .collect()
        })
    }

    /// The walls as segments: the arena's four edges if it has walls, then the segment walls
    /// (none on a periodic arena, where no solver uses them).
    fn walls(&self) -> impl Iterator<Item = (Wall, Segment)> + '_ {
        let Arena { min, max, .. } = *self.arena;
        let edges = [
            (ArenaWall::Bottom, min, DVec2::new(max.x, min.y)),
            (ArenaWall::Right, DVec2::new(max.x, min.y), max),
            (ArenaWall::Top, max, DVec2::new(min.x, max.y)),
            (ArenaWall::Left, DVec2::new(min.x, max.y), min),
        ];
        let edges = edges.into_iter().filter(|_| self.arena.has_walls());
        let segments = self.segments.0.iter().filter(|_| !self.arena.is_periodic());
        edges
            .map(|(side, a, b)| (Wall::Arena(side), Segment::new(a, b)))
            .chain(
                segments
                    .enumerate()
                    .map(|(k, s)| (Wall::Segment(k as u32), *s)),
            )
    }

    /// Runs `f` on the index, rebuilt first if it is out of date.
    fn with_index<R>(&self, f: impl FnOnce(&Built) -> R) -> R {
        let fresh =
            |built: &Built| !self.index.stale.load(Ordering::Acquire) && built.arena == *self.arena;
        let read = || {
            self.index
                .built
                .read()
                .unwrap_or_else(PoisonError::into_inner)
        };
        if !fresh(&read()) {
            let mut built = self
                .index
                .built
                .write()
                .unwrap_or_else(PoisonError::into_inner);
            if !fresh(&built) {
                let Built {
                    circles,
                    entities,
                    kinds,
                    arena,
                    scratch,
                } = &mut *built;
                entities.clear();
                kinds.clear();
                scratch.clear();
                for (entity, position, radius, layers, sensor) in &self.circles {
                    entities.push(entity);
                    kinds.push((layers.copied().unwrap_or_default().memberships, sensor));
                    scratch.push((position.0, radius.0));
                }
                *arena = *self.arena;
                circles.build(scratch, arena);
                self.index.stale.store(false, Ordering::Release);
            }
        }
        f(&read())
    }
}
