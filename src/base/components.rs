//! The components a circle is made of: `Position`, `Velocity`, `Radius`, `Mass`, `Tint`,
//! `Sleep`, `Rotation`, `AngularVelocity` and `CircleSerial`, and the optional `Restitution`
//! and `Friction`.
//!
//! `Position` is deliberately not `Transform`: the simulation owns it, and the render side copies
//! it into `Transform` only when rendering is on. Inserting a [`Radius`] is what makes an entity a
//! circle; it brings the other components with it (`#[require]`), so
//! `commands.spawn((Radius(0.5), Position(DVec2::ZERO)))` is a complete, resting, unit-mass circle.

use std::sync::atomic::{AtomicU64, Ordering};

use bevy::ecs::lifecycle::HookContext;
use bevy::ecs::world::DeferredWorld;
use bevy::math::DVec2;
use bevy::prelude::*;

/// Centre of a circle in arena coordinates.
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct Position(pub DVec2);

/// Linear velocity in arena units per second.
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct Velocity(pub DVec2);

/// Radius of a circle. Must be finite and positive; inserting it makes the entity a circle.
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
#[reflect(Component, Debug)]
#[require(
    Position,
    Velocity,
    Mass,
    Tint,
    Sleep,
    Rotation,
    AngularVelocity,
    CircleSerial
)]
pub struct Radius(pub f64);

/// Mass of a circle.
///
/// [`Mass::IMMOVABLE`] (infinite mass) makes the other two body kinds, under every solver:
/// - a **static** circle (an obstacle, a peg): immovable, at rest. Hits and forces never move
///   it; circles bounce off it as off a wall.
/// - a **kinematic** circle (a paddle): immovable, moving with the [`Velocity`] your code sets
///   (every frame if you like). It pushes the others and nothing pushes it back; what it gave
///   them is counted in [`PairCollisions`](crate::base::hits::PairCollisions)
///   (`immovable_work`, `immovable_impulse`). Like any circle it is kept inside the walls.
///
/// Immovable circles carry no energy or momentum in the diagnostics, and gravity and drag
/// leave them alone.
///
/// ```
/// use bevy::math::DVec2;
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// fn place(mut commands: Commands) {
///     // A peg, and a paddle that some other system steers by setting its velocity.
///     commands.spawn((Radius(0.1), Position(DVec2::new(0.0, 1.0)), Mass::IMMOVABLE));
///     commands.spawn((Radius(0.5), Position(DVec2::ZERO), Mass::IMMOVABLE, Velocity(DVec2::X)));
/// }
/// # bevy::ecs::system::assert_is_system(place);
/// ```
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct Mass(pub f64);

impl Default for Mass {
    fn default() -> Self {
        Self(1.0)
    }
}

impl Mass {
    /// Infinite mass: a static or kinematic circle.
    pub const IMMOVABLE: Mass = Mass(f64::INFINITY);

    /// Whether this is [`Mass::IMMOVABLE`] (any infinite mass).
    pub fn is_immovable(self) -> bool {
        !self.0.is_finite()
    }

    /// `1 / mass`, zero for an infinite mass. Collision kernels work with inverse masses so that
    /// immovable circles need no special case.
    pub fn inverse(self) -> f64 {
        if self.0.is_finite() {
            1.0 / self.0
        } else {
            0.0
        }
    }
}

/// A circle's own coefficient of restitution, in `[0, 1]`; without it a circle takes the
/// scene's (`effects.restitution` against circles, `effects.wall_restitution` against walls).
/// Two values meet as their minimum ([`combine_restitution`](crate::kernels::combine_restitution)),
/// against other circles and walls alike, under every solver.
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
#[reflect(Component, Debug)]
pub struct Restitution(pub f64);

/// How fast a circle turns, in radians per second, counter-clockwise positive. Every solver
/// turns a circle's [`Rotation`] by it; friction (under `soft`) changes it. A circle without
/// this component never turns: friction then acts on it as on a body that cannot roll.
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct AngularVelocity(pub f64);

/// How far a circle has turned since it was spawned: an angle in radians, counter-clockwise,
/// kept in `[-π, π]`. It changes nothing in the physics of a circle (a disc looks the same
/// at every angle); it is there so a game can draw a marked ball turning.
#[derive(Component, Reflect, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct Rotation(pub f64);

impl Rotation {
    /// This rotation turned on by `angle` radians, kept in `[-π, π]`.
    ///
    /// ```
    /// use moving_circles::prelude::*;
    ///
    /// let turned = Rotation(3.0).turned(1.0);
    /// assert!((turned.0 - (4.0 - std::f64::consts::TAU)).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn turned(self, angle: f64) -> Self {
        let a = self.0 + angle;
        if (-std::f64::consts::PI..=std::f64::consts::PI).contains(&a) {
            Self(a)
        } else {
            // `rem_euclid` keeps the angle's rounding to that of one addition per turn.
            let r = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
            Self(r - std::f64::consts::PI)
        }
    }
}

/// A circle's own moment of inertia about its centre (kg·m²): a hollow ring (`m r²`), a ball
/// with a heavy core, a wheel. Without it a circle turns as a uniform disc of its mass and
/// radius, `m r² / 2`. Contacts with friction (`soft`) and rough hits (`swept`, `exact`) turn
/// it through this; `f64::INFINITY` (or any value not above 0) keeps it from turning at all,
/// and a value so small that its inverse passes the range of numbers (below about 5.6e-309)
/// turns as the smallest whose inverse does not.
///
/// ```
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// let mut world = World::new();
/// // A ring of mass 1 and radius 0.5: all its mass at the rim.
/// world.spawn((Radius(0.5), Mass(1.0), Inertia(0.25)));
/// ```
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
#[reflect(Component, Debug)]
pub struct Inertia(pub f64);

/// A circle's own friction coefficient (Coulomb's μ, from 0 to
/// [`MAX_FRICTION`](crate::base::config::MAX_FRICTION), as the scene's: a checkpoint of a circle with
/// more is refused when read back); without it a circle takes
/// the scene's (`effects.friction` against circles, `effects.wall_friction` against walls).
/// Two values meet as the scene's `effects.friction_combine` says (their geometric mean by
/// default), against other circles and walls alike. Friction acts under the contact solver
/// `soft`; the other solvers treat circles as smooth.
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Deref, DerefMut)]
#[reflect(Component, Debug)]
pub struct Friction(pub f64);

/// Display colour of a circle as sRGB bytes, as in the plain-text particle format (`r g b`).
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Eq, Deref, DerefMut)]
#[reflect(Component, Default, Debug)]
pub struct Tint(pub [u8; 3]);

impl Default for Tint {
    fn default() -> Self {
        Self([230, 230, 230])
    }
}

/// Whether a circle sleeps, and how long it has been at rest. A sleeping circle is left where
/// it is by every solver, at no cost per step, and acts as an immovable circle at rest for the
/// others until it is woken: by a hit, by your code writing its [`Position`] or [`Velocity`],
/// or by a change of the effects, the arena, the segment walls or the solver. Only scenes with
/// gravity sleep ([`SleepConfig`](crate::base::config::SleepConfig)).
#[derive(
    Component, Reflect, Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize,
)]
#[reflect(Component, Default, Debug)]
pub struct Sleep {
    /// Where the circle was when it last moved: it is at rest while it stays near this point.
    pub anchor: DVec2,
    /// Seconds the circle has stayed near its anchor.
    pub slow_for: f64,
    /// Whether it sleeps now.
    pub asleep: bool,
}

/// The circles as every solver's systems read and write them (the discrete contact pass, the
/// wall bounce, the continuous step), in one query type so each sees them in the same order.
pub type SolverCircles<'w, 's> = Query<'w, 's, SolverData, With<CircleSerial>>;

/// What [`SolverCircles`] fetches of each circle.
pub type SolverData = (
    Entity,
    &'static mut Position,
    &'static mut Velocity,
    &'static Radius,
    &'static Mass,
    Option<&'static Restitution>,
    &'static Sleep,
);

/// How circles turn, as the solvers read and write it, in a query of its own so that a step
/// in which nothing turns pays nothing for it: each circle's angular velocity and rotation
/// (either may be absent: the circle then does not turn), its own friction and moment of
/// inertia, and whether it sleeps.
pub type SpinCircles<'w, 's> = Query<
    'w,
    's,
    (
        Option<&'static mut AngularVelocity>,
        Option<&'static mut Rotation>,
        Option<&'static Friction>,
        Option<&'static Inertia>,
        &'static Sleep,
    ),
    With<Radius>,
>;

/// A circle's place in the order every solver visits circles: given when the circle is
/// spawned, larger for every later circle, so the solvers see the circles in the order they
/// were spawned whatever tables Bevy keeps them in and whatever entity ids they have. That is
/// what makes a step's bits independent of the world's layout: a circle that gains or loses a
/// component moves to another table, and a world rebuilt from a checkpoint or a rollback
/// snapshot has new entities, yet each steps as the original.
///
/// Spawned without one (the default, [`CircleSerial::UNASSIGNED`]), a circle gets the next
/// free serial; spawned with one (a restored world), it keeps it, and later circles get larger
/// ones. Only the order of serials means anything: their values depend on what else the
/// process spawned.
#[derive(Component, Reflect, Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[reflect(Component, Default, Debug)]
#[component(on_insert = give_serial)]
pub struct CircleSerial(pub u64);

impl CircleSerial {
    /// The serial of a circle not yet given one.
    pub const UNASSIGNED: CircleSerial = CircleSerial(u64::MAX);
}

impl Default for CircleSerial {
    fn default() -> Self {
        Self::UNASSIGNED
    }
}

/// The next serial to give: one counter for the process, so serials grow in spawn order in
/// every world (a world sees gaps where another world spawned).
static NEXT_SERIAL: AtomicU64 = AtomicU64::new(0);

/// Gives a circle inserted without a serial the next one, and keeps the counter above a
/// serial given explicitly.
fn give_serial(mut world: DeferredWorld, context: HookContext) {
    let Some(mut serial) = world.get_mut::<CircleSerial>(context.entity) else {
        return;
    };
    if *serial == CircleSerial::UNASSIGNED {
        serial.0 = NEXT_SERIAL.fetch_add(1, Ordering::Relaxed);
    } else {
        NEXT_SERIAL.fetch_max(serial.0.saturating_add(1), Ordering::Relaxed);
    }
}

impl From<DVec2> for Position {
    fn from(v: DVec2) -> Self {
        Self(v)
    }
}

impl From<DVec2> for Velocity {
    fn from(v: DVec2) -> Self {
        Self(v)
    }
}
