//! Which circles meet which: [`CollisionLayers`] (membership and filter masks) and [`Sensor`]
//! (a circle that pushes nothing and meets nothing, and reports what overlaps it instead, in
//! its [`SensorOverlaps`] and as [`OverlapStarted`] / [`OverlapEnded`] messages).
//!
//! Every solver asks the same question of a pair, [`CollisionLayers::meets`], on the masks
//! [`CircleFilters`] gathers: a pair that does not meet is never resolved by a contact pass,
//! never predicted by the event engine, never a contact of the `soft` solver, never joins a
//! sleeping island and is not counted as an overlap. A scene in which no circle has layers or
//! is a sensor gathers nothing: every pair meets, as before.
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! const RED: u32 = 1 << 0;
//! const BLUE: u32 = 1 << 1;
//!
//! fn teams(mut commands: Commands) {
//!     // Red meets red, blue meets blue: the two fly through each other.
//!     let red = CollisionLayers::new(RED, RED);
//!     let blue = CollisionLayers::new(BLUE, BLUE);
//!     commands.spawn((Radius(0.5), Position(DVec2::new(-2.0, 0.0)), Velocity(DVec2::X), red));
//!     commands.spawn((Radius(0.5), Position(DVec2::new(2.0, 0.0)), Velocity(-DVec2::X), blue));
//!     assert!(!red.meets(blue));
//! }
//! # bevy::ecs::system::assert_is_system(teams);
//! ```

use bevy::ecs::system::SystemParam;
use bevy::math::DVec2;
use bevy::prelude::*;

use crate::base::components::{Position, Radius};

/// The groups a circle belongs to (`memberships`) and the groups it meets (`filters`), one bit
/// per group, up to 32 groups. Two circles meet when each is in a group the other meets
/// ([`CollisionLayers::meets`]). A circle without this component is in group 0 alone and meets
/// every group ([`CollisionLayers::DEFAULT`]), so a team in other groups that leaves group 0
/// out of its filters passes through every plain circle.
#[derive(
    Component,
    Reflect,
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    serde::Serialize,
    serde::Deserialize,
)]
#[reflect(Component, Default, Debug)]
pub struct CollisionLayers {
    /// The groups this circle is in.
    pub memberships: u32,
    /// The groups this circle meets.
    pub filters: u32,
}

impl CollisionLayers {
    /// In group 0, meeting every group: the layers of a circle without the component.
    pub const DEFAULT: Self = Self::new(1, u32::MAX);
    /// In every group, meeting every group.
    pub const ALL: Self = Self::new(u32::MAX, u32::MAX);
    /// In no group, meeting none: what a [`Sensor`] is to the solvers.
    pub const NONE: Self = Self::new(0, 0);

    /// Layers with these masks.
    pub const fn new(memberships: u32, filters: u32) -> Self {
        Self {
            memberships,
            filters,
        }
    }

    /// Whether a circle of these layers and one of `other` meet: each is in a group the other
    /// meets. Symmetric.
    ///
    /// ```
    /// use moving_circles::prelude::CollisionLayers;
    ///
    /// let ghost = CollisionLayers::new(0b10, 0b10); // meets only its own kind
    /// assert!(ghost.meets(ghost));
    /// assert!(!ghost.meets(CollisionLayers::DEFAULT)); // a plain circle is in group 0 alone
    /// assert!(ghost.meets(CollisionLayers::ALL));
    /// assert!(!CollisionLayers::NONE.meets(CollisionLayers::ALL));
    /// ```
    #[inline]
    pub const fn meets(self, other: Self) -> bool {
        self.memberships & other.filters != 0 && other.memberships & self.filters != 0
    }
}

impl Default for CollisionLayers {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Makes a circle a sensor: it gives and takes no impulse (no solver pairs it with anything),
/// still moves with its velocity and still bounces off walls unless static or kinematic
/// ([`Mass::IMMOVABLE`](crate::base::components::Mass::IMMOVABLE)). After each fixed step, the
/// [`SensorPlugin`](crate::game::sensor::SensorPlugin) lists the circles overlapping it in its
/// [`SensorOverlaps`] (those its own [`CollisionLayers`], if it has them, meet; never another
/// sensor) and writes an [`OverlapStarted`] or [`OverlapEnded`] message for each that came or
/// went.
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Eq)]
#[reflect(Component, Default, Debug)]
#[require(SensorOverlaps)]
pub struct Sensor;

/// The circles a [`Sensor`] overlapped at the end of the last fixed step, sorted.
#[derive(Component, Clone, Debug, Default, PartialEq, Eq)]
pub struct SensorOverlaps(pub(crate) Vec<Entity>);

impl SensorOverlaps {
    /// The circles overlapping the sensor, sorted by entity.
    pub fn circles(&self) -> &[Entity] {
        &self.0
    }

    /// Whether `circle` overlaps the sensor.
    pub fn contains(&self, circle: Entity) -> bool {
        self.0.binary_search(&circle).is_ok()
    }
}

/// A circle began overlapping a sensor in the last fixed step.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OverlapStarted {
    /// The sensor.
    pub sensor: Entity,
    /// The circle now overlapping it.
    pub circle: Entity,
}

/// A circle stopped overlapping a sensor in the last fixed step: it left, was despawned, became
/// a sensor, or one of the two changed layers so that they no longer meet.
#[derive(Message, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OverlapEnded {
    /// The sensor.
    pub sensor: Entity,
    /// The circle that overlapped it.
    pub circle: Entity,
}

/// The circles that have layers or are sensors (none in a scene without layers).
pub type Layered = (With<Radius>, Or<(With<CollisionLayers>, With<Sensor>)>);

/// What the overlap measures read of a circle: centre, radius, layers, sensor.
pub type LayeredDisc = (
    &'static Position,
    &'static Radius,
    Option<&'static CollisionLayers>,
    Has<Sensor>,
);

/// A [`LayeredDisc`] as centre, radius and the layers the solvers give it ([`solver_layers`]).
pub fn layered_disc(
    (position, radius, layers, sensor): (&Position, &Radius, Option<&CollisionLayers>, bool),
) -> (DVec2, f64, CollisionLayers) {
    (position.0, radius.0, solver_layers(layers, sensor))
}

/// Each circle's layers as the solvers see them ([`solver_layers`]).
#[derive(SystemParam)]
pub struct CircleFilters<'w, 's> {
    any: Query<'w, 's, (), Layered>,
    each: Query<'w, 's, (Option<&'static CollisionLayers>, Has<Sensor>), With<Radius>>,
}

impl CircleFilters<'_, '_> {
    /// Whether any circle has layers or is a sensor. If not, every pair meets and a solver
    /// gathers nothing.
    pub fn any(&self) -> bool {
        !self.any.is_empty()
    }

    /// The layers circle `entity` meets others with ([`solver_layers`]).
    pub fn of(&self, entity: Entity) -> CollisionLayers {
        match self.each.get(entity) {
            Ok((layers, sensor)) => solver_layers(layers, sensor),
            Err(_) => CollisionLayers::DEFAULT,
        }
    }

    /// The layers of each of `entities`, in order, or nothing when no circle has layers or is
    /// a sensor (every pair meets).
    pub fn gather(&self, entities: impl IntoIterator<Item = Entity>) -> Vec<CollisionLayers> {
        match self.any() {
            true => entities.into_iter().map(|e| self.of(e)).collect(),
            false => Vec::new(),
        }
    }
}

/// The layers the solvers give a circle with these components: none for a sensor, its own, or
/// [`CollisionLayers::DEFAULT`] for a circle without.
#[inline]
pub fn solver_layers(layers: Option<&CollisionLayers>, sensor: bool) -> CollisionLayers {
    match (layers, sensor) {
        (_, true) => CollisionLayers::NONE,
        (Some(layers), false) => *layers,
        (None, false) => CollisionLayers::DEFAULT,
    }
}

/// Whether a circle of these layers can meet any circle at all (a sensor's cannot).
#[inline]
pub fn meets_any(layers: CollisionLayers) -> bool {
    layers.memberships != 0 && layers.filters != 0
}

/// Whether circle `i` can meet any circle, given each circle's layers (`layers` empty: every
/// circle can): the circles the event engine sizes its cells for.
#[inline]
pub fn can_meet(layers: &[CollisionLayers], i: usize) -> bool {
    layers.is_empty() || meets_any(layers[i])
}

/// Whether circles `i` and `j` meet, given each circle's layers (`layers` empty: all meet, as
/// circles without layers do).
#[inline]
pub fn pair_meets(layers: &[CollisionLayers], i: usize, j: usize) -> bool {
    layers.is_empty() || layers[i].meets(layers[j])
}
