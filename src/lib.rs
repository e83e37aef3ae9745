#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod accuracy;
pub mod arena;
pub mod boundary;
pub mod checkpoint;
pub mod circle;
pub mod collide;
pub mod commands;
pub mod components;
pub mod config;
pub mod diagnostics;
pub mod effects;
pub mod eos;
pub mod error;
pub mod exact;
pub mod figure;
pub mod forces;
pub mod grid;
pub mod hits;
pub mod integrate;
pub mod io;
pub mod lattice;
pub mod range;
#[cfg(feature = "render")]
pub mod render;
pub mod run;
pub mod scene;
pub mod schedule;
pub mod segment;
pub mod spawn;

use bevy::app::{PluginGroup, PluginGroupBuilder};

use boundary::{PeriodicPlugin, SegmentsPlugin, WallsPlugin};
use collide::CollidePlugin;
use config::CirclesConfig;
use diagnostics::DiagnosticsPlugin;
use exact::ContinuousPlugin;
use forces::{DragPlugin, GravityPlugin};
use integrate::IntegratePlugin;
use schedule::StepPlugin;
use spawn::SpawnPlugin;

/// The common imports: the plugin group and its parts, components, configuration, sets and
/// what the simulation measures.
pub mod prelude {
    pub use crate::CirclesPlugins;
    pub use crate::arena::{Arena, Boundary};
    pub use crate::boundary::{PeriodicPlugin, SegmentsPlugin, WallCollisions, WallsPlugin};
    pub use crate::circle::CircleState;
    pub use crate::collide::{CollidePlugin, PairCollisions};
    pub use crate::components::{Mass, Position, Radius, Restitution, Tint, Velocity};
    pub use crate::config::{
        CirclesConfig, DropConfig, Effects, MassModel, Placement, Solver, SpawnConfig,
    };
    pub use crate::diagnostics::{CircleDiagnostics, DiagnosticsPlugin, Measuring};
    pub use crate::effects::Effect;
    pub use crate::exact::ContinuousPlugin;
    pub use crate::forces::{DragPlugin, GravityPlugin};
    pub use crate::hits::{ArenaWall, CircleHit, Wall, WallHit};
    pub use crate::integrate::IntegratePlugin;
    pub use crate::scene::Scene;
    pub use crate::schedule::{CircleStep, CircleSystems, ContinuousStep, StepPlugin, StepTotals};
    pub use crate::segment::{Segment, Segments};
    pub use crate::spawn::{Respawn, SpawnPlugin, SpawnReport};
}

pub use components::{Mass, Position, Radius, Restitution, Tint, Velocity};
pub use schedule::CircleSystems;

/// The simulation as a plugin group: [`StepPlugin`] (first: the others build on it),
/// [`SpawnPlugin`], [`IntegratePlugin`], one plugin per effect ([`GravityPlugin`],
/// [`DragPlugin`], [`SegmentsPlugin`], [`WallsPlugin`], [`PeriodicPlugin`], [`CollidePlugin`]),
/// [`ContinuousPlugin`] (the `swept` and `exact` solvers) and [`DiagnosticsPlugin`].
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
        } = self.config;
        PluginGroupBuilder::start::<Self>()
            .add(StepPlugin {
                arena,
                solver,
                effects,
                dt,
                segments,
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
            .add(ContinuousPlugin)
            .add(DiagnosticsPlugin)
    }
}
