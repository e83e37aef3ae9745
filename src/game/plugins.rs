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
