//! Moving, colliding circles on [Bevy](https://bevy.org) 0.19, built the ECS way: an engine you
//! embed as a plugin group ([`CirclesPlugins`]), five solvers from a cheap discrete step to an
//! exact event-driven one and a contact solver for piles, and the headless runs and studies the `moving_circles` binary is made
//! of ([`run`], [`commands`]).
//!
//! # Getting started
//!
//! Add the plugin group to an app and give it a [`CirclesConfig`]: the
//! arena, what to spawn, the solver and the effects. Everything a user needs is in the
//! [`prelude`].
//!
//! ```no_run
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! App::new()
//!     .add_plugins(DefaultPlugins)
//!     .add_plugins(CirclesPlugins::new(CirclesConfig {
//!         spawn: SpawnConfig { count: 1000, radius: (0.05, 0.15), ..default() },
//!         solver: Solver::Substeps(4),
//!         ..default()
//!     }))
//!     // Draw, HUD and controls, if you want ours (feature `render`):
//!     .add_plugins(moving_circles::render::CirclesRenderPlugin)
//!     .run();
//! ```
//!
//! Headless, [`run::headless_app`] builds the app the tests and the command line step: every
//! `update()` is exactly one fixed step. Circles are entities with a [`Position`], a
//! [`Velocity`] and a [`Radius`] (which brings the rest); with
//! [`Effects::hit_messages`](config::Effects::hit_messages) on, each hit is a
//! [`CircleHit`](hits::CircleHit) or [`WallHit`](hits::WallHit) message:
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! let mut app = moving_circles::run::headless_app(CirclesConfig {
//!     effects: Effects { hit_messages: true, ..default() },
//!     solver: Solver::Exact,
//!     ..default()
//! });
//! let mut spawn = |x: f64, v: DVec2| {
//!     app.world_mut().spawn((Radius(0.5), Position(DVec2::new(x, 0.0)), Velocity(v))).id()
//! };
//! let (a, b) = (spawn(-1.0, DVec2::X), spawn(1.0, -DVec2::X));
//! let mut hits = Vec::new();
//! for _ in 0..60 {
//!     app.update(); // one fixed step
//!     let messages = app.world().resource::<Messages<CircleHit>>();
//!     hits.extend(messages.iter_current_update_messages().copied());
//! }
//! assert_eq!(hits.len(), 1);
//! assert!([hits[0].a, hits[0].b] == [a, b] || [hits[0].a, hits[0].b] == [b, a]);
//! assert_eq!(hits[0].impulse, 2.0); // unit masses meeting at 1 + 1, elastic
//! assert_eq!(app.world().resource::<PairCollisions>().count, 1);
//! ```
//!
//! A scene file says the same in RON; [`Scene::parse`](scene::Scene::parse) reads one and
//! [`Scene::to_config`](scene::Scene::to_config) checks it, naming the field of any bad value:
//!
//! ```
//! use moving_circles::prelude::*;
//!
//! let scene = Scene::parse(
//!     "(arena: (size: (8.0, 6.0)),
//!       segments: [[(-3.0, 2.0), (0.0, -1.0), (3.0, 2.0)]],      // a V: two segment walls
//!       circles: [(position: (-1.0, 1.5), velocity: (0.0, -4.0), radius: 0.2)],
//!       solver: \"exact\")",
//!     "v.ron",
//! )
//! .unwrap();
//! let config = scene.to_config("v.ron").unwrap();
//! assert_eq!(config.segments.0.len(), 2);
//! let mut app = moving_circles::run::headless_app(config);
//! for _ in 0..30 {
//!     app.update();
//! }
//! assert!(app.world().resource::<WallCollisions>().count >= 1);
//!
//! let bad = Scene::parse("(dt: -1.0)", "bad.ron").unwrap().to_config("bad.ron");
//! assert!(bad.unwrap_err().to_string().contains("dt"));
//! ```
//!
//! # Solvers
//!
//! Picked by [`Solver`](config::Solver), per scene, on the command line or at runtime:
//!
//! | solver | what it does |
//! |---|---|
//! | `discrete` | moves, pushes overlapping pairs apart and applies the elastic impulse ([`collide`]): the cheapest, but circles overlap and fast pairs tunnel. |
//! | `substeps=N` | runs `discrete` N times a step with dt/N: errors shrink roughly like 1/N while the cost grows like N. |
//! | `swept` | processes each step's pair and wall hits in time order at their times of impact ([`exact`]), afresh every step: no tunnelling, no overlap. |
//! | `exact` | keeps one event-driven engine ([`exact::engine`]) across steps: the reference, exact to rounding, paying per collision rather than per step. |
//! | `soft` | the contact solver for games and piles ([`soft`]): persistent speculative contacts made soft springs, warm started and solved in 4 substeps (`soft=N`: N) with relaxation and a restitution pass, so stacks and piles rest. |
//!
//! # Modules
//!
//! The plugin group and what it is made of:
//! - [`schedule`]: the [`CircleSystems`] sets, the step schedules and [`StepPlugin`];
//! - [`config`]: [`CirclesConfig`] and its parts, with the limits on every value;
//! - [`components`]: the components a circle is made of;
//! - [`spawn`]: placing circles at startup, on a respawn and one at a time;
//! - [`integrate`]: free flight;
//! - [`forces`]: gravity and drag;
//! - [`boundary`]: walls, periodic edges and segment walls;
//! - [`collide`]: circle-circle collisions of the discrete solvers, the broad phase and the contact kernel;
//! - [`exact`]: the continuous solvers, `swept` and `exact`, on one event engine;
//! - [`soft`]: the contact solver, `soft`;
//! - [`sleep`]: circles at rest fall asleep under the time-stepped solvers;
//! - [`effects`]: the registry that keeps exactly the effects a scene calls for in the schedule;
//! - [`hits`]: collision messages;
//! - [`diagnostics`]: energy, momentum and pressure after each step;
//! - [`transform_sync`]: each circle's `Transform` follows its position, interpolated between steps;
//! - [`query`]: spatial queries for game code: points, overlaps, ray and circle casts;
//! - [`render`]: the window, sprites, HUD, keys and the live panel (feature `render`).
//!
//! The plain data the kernels work on:
//! - [`arena`]: the region the circles live in, walls or periodic;
//! - [`circle`]: one circle's state outside the ECS;
//! - [`segment`]: segment walls and the cells they pass near;
//! - [`error`]: the errors of bad input.
//!
//! Files, runs and studies:
//! - [`scene`]: scene files and particle files, read and checked;
//! - [`io`]: writing outputs atomically and reading inputs of untrusted size;
//! - [`run`]: the headless app and the one stepping loop;
//! - [`checkpoint`]: a run's whole state, to resume bit for bit;
//! - [`commands`] (feature `cli`): the work behind each `moving_circles` command;
//! - [`accuracy`]: the accuracy study of every solver against `exact`;
//! - [`eos`]: the hard-disk equation of state.
//!
//! Internal to the crate (see `docs/architecture.md`): the uniform grid every part that buckets
//! circles shares, triangular lattices for dense states, the one physical range of every input
//! value (its limits are re-exported by [`config`]) and what the studies' figures share.
//!
//! # The guide
//!
//! The repository's `README.md` is the front door; its `docs/` folder holds one page per
//! concern, each figure with the command that made it: `docs/cli.md` (the app, headless runs,
//! scenes, the configuration reference), `docs/solvers.md` (the accuracy study and what to
//! pick), `docs/physics.md`, `docs/embedding.md`, `docs/robustness.md`, `docs/performance.md`,
//! `docs/architecture.md`, `docs/testing.md` and `docs/history.md`; `benches/README.md`
//! describes the benchmarks.
#![warn(missing_docs)]

// The Rust examples of the README and of the guide's embedding page, compiled and run as
// doctests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
#[cfg(doctest)]
#[doc = include_str!("../docs/embedding.md")]
struct EmbeddingDoctests;

pub mod accuracy;
pub mod arena;
pub mod boundary;
pub mod checkpoint;
pub mod circle;
pub mod collide;
pub mod collision_layers;
#[cfg(feature = "cli")]
pub mod commands;
pub mod components;
pub mod config;
pub mod diagnostics;
pub mod effects;
pub mod eos;
pub mod error;
pub mod exact;
#[cfg(feature = "cli")]
mod figure;
pub mod forces;
mod grid;
pub mod hits;
pub mod integrate;
pub mod io;
mod lattice;
pub mod query;
mod range;
#[cfg(feature = "render")]
pub mod render;
pub mod run;
pub mod scene;
pub mod schedule;
pub mod segment;
pub mod sensor;
pub mod sleep;
pub mod soft;
pub mod spawn;
pub mod transform_sync;
pub mod vector;

use bevy::app::{PluginGroup, PluginGroupBuilder};

use boundary::{PeriodicPlugin, SegmentsPlugin, WallsPlugin};
use collide::CollidePlugin;
use config::CirclesConfig;
use diagnostics::DiagnosticsPlugin;
use exact::ContinuousPlugin;
use forces::{DragPlugin, GravityPlugin};
use integrate::IntegratePlugin;
use query::SpatialQueryPlugin;
use schedule::StepPlugin;
use sensor::SensorPlugin;
use sleep::SleepPlugin;
use soft::SoftPlugin;
use spawn::SpawnPlugin;
use transform_sync::TransformSyncPlugin;

/// The common imports: the plugin group and its parts, components, configuration, sets and
/// what the simulation measures.
pub mod prelude {
    pub use crate::CirclesPlugins;
    pub use crate::arena::{Arena, Boundary};
    pub use crate::boundary::{PeriodicPlugin, SegmentsPlugin, WallCollisions, WallsPlugin};
    pub use crate::circle::CircleState;
    pub use crate::collide::{CollidePlugin, PairCollisions};
    pub use crate::collision_layers::{
        CollisionLayers, OverlapEnded, OverlapStarted, Sensor, SensorOverlaps,
    };
    pub use crate::components::{
        AngularVelocity, Friction, Inertia, Mass, Position, Radius, Restitution, Rotation, Sleep,
        Tint, Velocity,
    };
    pub use crate::config::{
        CirclesConfig, Combine, DropConfig, Effects, MassModel, Placement, SleepConfig, SoftConfig,
        Solver, SpawnConfig,
    };
    pub use crate::diagnostics::{CircleDiagnostics, DiagnosticsPlugin, Measuring};
    pub use crate::effects::Effect;
    pub use crate::exact::{ContinuousPlugin, EventBudget};
    pub use crate::forces::{DragPlugin, GravityPlugin};
    pub use crate::hits::{ArenaWall, CircleHit, Wall, WallHit};
    pub use crate::integrate::IntegratePlugin;
    pub use crate::query::{CastHit, QueryFilter, SpatialQuery, SpatialQueryPlugin, Target};
    pub use crate::scene::Scene;
    pub use crate::schedule::{CircleStep, CircleSystems, ContinuousStep, StepPlugin, StepTotals};
    pub use crate::segment::{Segment, Segments};
    pub use crate::sensor::SensorPlugin;
    pub use crate::sleep::{SleepPlugin, Sleeping};
    pub use crate::soft::SoftPlugin;
    pub use crate::spawn::{Respawn, SpawnPlugin, SpawnReport};
    pub use crate::transform_sync::{DefaultSmoothing, Smoothing, TransformSyncPlugin};
}

pub use components::{
    AngularVelocity, Friction, Inertia, Mass, Position, Radius, Restitution, Rotation, Tint,
    Velocity,
};
pub use schedule::CircleSystems;

/// The simulation as a plugin group: [`StepPlugin`] (first: the others build on it),
/// [`SpawnPlugin`], [`IntegratePlugin`], one plugin per effect ([`GravityPlugin`],
/// [`DragPlugin`], [`SegmentsPlugin`], [`WallsPlugin`], [`PeriodicPlugin`], [`CollidePlugin`]),
/// [`ContinuousPlugin`] (the `swept` and `exact` solvers), [`SoftPlugin`] (the `soft` contact
/// solver), [`SleepPlugin`], [`SensorPlugin`] (what overlaps each
/// [`Sensor`](collision_layers::Sensor)), [`DiagnosticsPlugin`], [`TransformSyncPlugin`] (each circle's
/// `Transform`, if it has one, follows its [`Position`] smoothly between fixed steps) and
/// [`SpatialQueryPlugin`] (the index behind [`SpatialQuery`](query::SpatialQuery)).
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
            .add(ContinuousPlugin)
            .add(SoftPlugin)
            .add(SleepPlugin)
            .add(SensorPlugin)
            .add(DiagnosticsPlugin)
            .add(TransformSyncPlugin::default())
            .add(SpatialQueryPlugin)
    }
}
