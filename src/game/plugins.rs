//! [`CirclesPlugins`], the plugin group that composes the simulation: the step every solver
//! shares, one plugin per effect and per solver, and the game surface above them.

use bevy::app::{PluginGroup, PluginGroupBuilder};

use crate::base::config::CirclesConfig;
use crate::game::diagnostics::DiagnosticsPlugin;
use crate::game::query::SpatialQueryPlugin;
use crate::game::sensor::SensorPlugin;
use crate::game::spawn::SpawnPlugin;
use crate::game::transform_sync::TransformSyncPlugin;
use crate::solvers::discrete::{CollidePlugin, DiscretePlugin};
use crate::solvers::exact::ContinuousPlugin;
use crate::solvers::soft::SoftPlugin;
use crate::step::boundary::{PeriodicPlugin, SegmentsPlugin, WallsPlugin};
use crate::step::forces::{DragPlugin, GravityPlugin};
use crate::step::integrate::IntegratePlugin;
use crate::step::schedule::StepPlugin;
use crate::step::sleep::SleepPlugin;

/// The simulation as a plugin group: [`StepPlugin`] (first: the others build on it),
/// [`SpawnPlugin`], [`IntegratePlugin`], one plugin per effect ([`GravityPlugin`],
/// [`DragPlugin`], [`SegmentsPlugin`], [`WallsPlugin`], [`PeriodicPlugin`], [`CollidePlugin`]),
/// one plugin per solver ([`DiscretePlugin`]: `discrete` and `substeps=N`;
/// [`ContinuousPlugin`]: `swept` and `exact`; [`SoftPlugin`]: the `soft` contact
/// solver), [`SleepPlugin`], [`SensorPlugin`] (what overlaps each
/// [`Sensor`](crate::base::collision_layers::Sensor)), [`DiagnosticsPlugin`], [`TransformSyncPlugin`] (each circle's
/// `Transform`, if it has one, follows its [`Position`](crate::base::components::Position) smoothly between fixed steps) and
/// [`SpatialQueryPlugin`] (the index behind [`SpatialQuery`](crate::game::query::SpatialQuery)).
///
/// An effect plugin schedules its systems only when the configuration calls for the effect,
/// so an effect a scene does not ask for costs nothing; it stays registered, so a reloaded
/// scene that asks for it gets its systems. Parts can be switched off or replaced the Bevy way:
///
/// ```no_run
/// # use bevy::prelude::*;
/// # use moving_circles::prelude::*;
/// App::new().add_plugins((
///     MinimalPlugins,
///     CirclesPlugins::default().build().disable::<SpawnPlugin>(),
/// ));
/// ```
///
/// Walls are the arena's: a game without them takes an open arena
/// ([`CirclesConfig`]'s docs), which every solver follows. [`WallsPlugin`] is only the
/// time-stepped solvers' wall system, so disabling it leaves `soft`, `swept` and `exact`
/// bouncing off the walls.
///
/// # Changing things while it runs
///
/// A system of yours may write the [`Effects`](crate::base::config::Effects),
/// [`Arena`](crate::base::arena::Arena), [`Segments`](crate::base::segment::Segments) or
/// [`Solver`](crate::base::config::Solver) resources at any time: before each step
/// (`FixedFirst`) the group reconciles the effects' systems with them if any changed, the one
/// path a reloaded scene and the panel take too. Gravity switched on gets its system, an arena
/// made periodic swaps the walls' system for the periodic edges', a first segment wall brings
/// the segment system; the event engine and the contact solver compare the settings they were
/// built for and rebuild when they differ (`tests/suite/game_changes.rs` makes each change from
/// an `Update` system under all five solvers).
///
/// A checkpoint (`Checkpoint::take`, feature `tools`) taken between your writes and the step
/// that applies them holds the state as you left it, and the resumed run does with your writes
/// what that step would have. It keeps what your code gave circles of their own
/// (`Restitution`, `Friction`, `Inertia`, `CollisionLayers`, a `Sensor` with the circles it
/// overlaps), checked as every value is, and the resumed run goes on bit for bit under every
/// solver, whatever parts the circles have: the solvers take circles in spawn order, not in
/// Bevy's table order. Under `exact`, where circles have layers or sensors, the checkpoint
/// keeps no engine and the resumed run builds one, so it goes on equal to rounding
/// (`tests/suite/resume.rs`). The [`EventBudget`](crate::solvers::exact::EventBudget) and the
/// thread count are settings of the app, not of the state: a checkpoint does not carry them.
///
/// Your systems may also spawn, despawn and teleport circles and change their velocity, radius
/// or mass between steps (outside
/// [`CircleSystems::Step`](crate::step::schedule::CircleSystems::Step)), under every solver.
/// The discrete solvers gather the circles afresh every (sub)step; `swept` builds its event
/// engine every step (keeping it only while nothing in it moves and nothing outside touched a
/// circle); `exact` keeps its engine across steps and updates it in place when a few circles
/// were moved or steered from outside (one re-prediction each), and rebuilds it when circles
/// were spawned or despawned, a radius, mass, restitution or moment of inertia changed, or most
/// circles changed (a force effect). It finds them with Bevy's change filters, so a step nobody
/// touched looks closely at none; it says which in a debug log
/// (`RUST_LOG=moving_circles=debug`) and counts both in `EngineState::{rebuilds, updates}`.
/// `tests/suite/bodies.rs` spawns and despawns one circle per step for 600 steps, teleporting,
/// growing or re-aiming another, under each solver: no overlap under `swept` and `exact` (1e-9
/// of a radius), and no message names a despawned circle.
///
/// ```
/// use bevy::math::DVec2;
/// use bevy::prelude::*;
/// use moving_circles::prelude::*;
///
/// /// A circle past x = 7 leaves, and a new one like it comes in at the left edge.
/// fn recycle(mut commands: Commands, circles: Query<(Entity, &Position, &Radius)>) {
///     for (entity, position, radius) in &circles {
///         if position.0.x > 7.0 {
///             commands.entity(entity).despawn();
///             let entry = DVec2::new(-7.0, position.0.y);
///             commands.spawn((Radius(radius.0), Position(entry), Velocity(DVec2::X)));
///         }
///     }
/// }
/// # bevy::ecs::system::assert_is_system(recycle);
/// // app.add_systems(FixedUpdate, recycle.before(CircleSystems::Step));
/// ```
#[derive(Clone, Debug, Default)]
pub struct CirclesPlugins {
    /// What to simulate and how.
    pub config: CirclesConfig,
}

impl CirclesPlugins {
    /// The plugin group for `config`.
    pub fn new(config: CirclesConfig) -> Self {
        Self { config }
    }
}

impl PluginGroup for CirclesPlugins {
    fn build(self) -> PluginGroupBuilder {
        let CirclesConfig {
            arena,
            spawn,
            solver,
            effects,
            dt,
            circles,
            segments,
            drop,
            soft,
        } = self.config;
        PluginGroupBuilder::start::<Self>()
            .add(StepPlugin {
                arena,
                solver,
                effects,
                dt,
                segments,
                soft,
            })
            .add(SpawnPlugin {
                config: spawn,
                circles,
                drop,
            })
            .add(IntegratePlugin)
            .add(GravityPlugin)
            .add(DragPlugin)
            .add(SegmentsPlugin)
            .add(WallsPlugin)
            .add(PeriodicPlugin)
            .add(CollidePlugin)
            .add(DiscretePlugin)
            .add(ContinuousPlugin)
            .add(SoftPlugin)
            .add(SleepPlugin)
            .add(SensorPlugin)
            .add(DiagnosticsPlugin)
            .add(TransformSyncPlugin::default())
            .add(SpatialQueryPlugin)
    }
}
