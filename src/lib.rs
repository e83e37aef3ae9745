//! # moving_circles
//!
//! Moving, colliding circles on Bevy 0.19, built the ECS way: circles are entities with
//! [`Position`], [`Velocity`], [`Radius`] and [`Mass`]; small plugins each own one concern
//! (spawning, integration, walls, collisions, diagnostics) and [`CirclesPlugins`] composes
//! only the ones a configuration calls for.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! App::new()
//!     .add_plugins(MinimalPlugins)
//!     .add_plugins(CirclesPlugins::new(CirclesConfig {
//!         spawn: SpawnConfig { count: 500, ..default() },
//!         ..default()
//!     }))
//!     .run();
//! ```
//!
//! Module map (data flows top to bottom every fixed step):
//! - [`components`]: what a circle is made of.
//! - [`config`]: plain settings structs (arena, spawn, solver, effects).
//! - [`schedule`]: the [`CircleSystems`] sets, the [`CircleStep`](schedule::CircleStep) substep
//!   schedule and the core [`StepPlugin`].
//! - [`spawn`]: seeded non-overlapping placement.
//! - [`integrate`]: `x += v·dt`.
//! - [`boundary`]: wall reflection.
//! - [`collide`]: broad phase (cell list), contact kernel, the collision system (`discrete`).
//! - [`exact`]: the event-driven engine behind the `swept` and `exact` solvers.
//! - [`diagnostics`]: energy, momentum, collision counters.
//! - `render` (feature `render`): window, drawing, HUD, input, screenshots.
#![warn(missing_docs)]

pub mod accuracy;
pub mod boundary;
pub mod collide;
pub mod components;
pub mod config;
pub mod diagnostics;
pub mod effects;
pub mod exact;
pub mod integrate;
#[cfg(feature = "render")]
pub mod render;
pub mod run;
pub mod scene;
pub mod schedule;
pub mod spawn;

use bevy::app::{PluginGroup, PluginGroupBuilder};

use boundary::{PeriodicPlugin, WallsPlugin};
use collide::CollidePlugin;
use config::CirclesConfig;
use diagnostics::DiagnosticsPlugin;
use effects::{DragPlugin, Effect, GravityPlugin};
use exact::ContinuousPlugin;
use integrate::IntegratePlugin;
use schedule::StepPlugin;
use spawn::SpawnPlugin;

/// The common imports: components, config, plugins and system sets.
pub mod prelude {
    pub use crate::CirclesPlugins;
    pub use crate::boundary::{PeriodicPlugin, WallsPlugin};
    pub use crate::collide::CollidePlugin;
    pub use crate::components::{Mass, Position, Radius, Tint, Velocity};
    pub use crate::config::{
        Arena, Boundary, CirclesConfig, Effects, MassModel, Solver, SpawnConfig,
    };
    pub use crate::diagnostics::{CircleDiagnostics, CollisionCounters, DiagnosticsPlugin};
    pub use crate::effects::{DragPlugin, Effect, GravityPlugin};
    pub use crate::exact::ContinuousPlugin;
    pub use crate::integrate::IntegratePlugin;
    pub use crate::scene::Scene;
    pub use crate::schedule::{CircleStep, CircleSystems, ContinuousStep, StepPlugin};
    pub use crate::spawn::{Respawn, SpawnPlugin, SpawnReport};
}

pub use components::{Mass, Position, Radius, Tint, Velocity};
pub use schedule::CircleSystems;

/// The simulation as a plugin group: [`StepPlugin`], [`SpawnPlugin`], [`IntegratePlugin`],
/// [`DiagnosticsPlugin`], and one plugin per effect the configuration calls for:
/// [`GravityPlugin`], [`DragPlugin`], [`WallsPlugin`] or [`PeriodicPlugin`], [`CollidePlugin`].
///
/// Effects a configuration does not call for are not added at all, so they cost nothing.
/// Parts can be switched off or replaced the Bevy way:
///
/// ```no_run
/// # use bevy::prelude::*;
/// # use moving_circles::prelude::*;
/// App::new().add_plugins((
///     MinimalPlugins,
///     CirclesPlugins::default().build().disable::<SpawnPlugin>(),
/// ));
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
        } = self.config;
        let mut group = PluginGroupBuilder::start::<Self>()
            .add(StepPlugin {
                arena,
                solver,
                effects,
                dt,
            })
            .add(SpawnPlugin {
                config: spawn,
                circles,
            })
            .add(IntegratePlugin)
            .add(ContinuousPlugin)
            .add(DiagnosticsPlugin);
        for effect in Effect::called_for(&effects) {
            group = match effect {
                Effect::Gravity => group.add(GravityPlugin),
                Effect::Drag => group.add(DragPlugin),
                Effect::Walls => group.add(WallsPlugin),
                Effect::Periodic => group.add(PeriodicPlugin),
                Effect::Collisions => group.add(CollidePlugin),
            };
        }
        group
    }
}
