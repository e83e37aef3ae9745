//! Moving, colliding circles on [Bevy](https://bevy.org) 0.19, built the ECS way: an engine you
//! embed as a plugin group ([`CirclesPlugins`]), five solvers from a cheap discrete step to an
//! exact event-driven one and a contact solver for piles, and the headless runs and studies the
//! `moving_circles` binary is made of ([`tools`], [`cli`]).
//!
//! # Getting started
//!
//! Add the plugin group to an app and give it a [`CirclesConfig`](base::config::CirclesConfig): the
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
//! Headless, [`tools::run::headless_app`] builds the app the tests and the command line step: every
//! `update()` is exactly one fixed step. Circles are entities with a [`Position`], a
//! [`Velocity`] and a [`Radius`] (which brings the rest); with
//! [`Effects::hit_messages`](base::config::Effects::hit_messages) on, each hit is a
//! [`CircleHit`](base::hits::CircleHit) or [`WallHit`](base::hits::WallHit) message:
//!
//! ```
//! use bevy::math::DVec2;
//! use bevy::prelude::*;
//! use moving_circles::prelude::*;
//!
//! let mut app = moving_circles::tools::run::headless_app(CirclesConfig {
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
//! A scene file says the same in RON; [`Scene::parse`](tools::scene::Scene::parse) reads one and
//! [`Scene::to_config`](tools::scene::Scene::to_config) checks it, naming the field of any bad value:
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
//! let mut app = moving_circles::tools::run::headless_app(config);
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
//! Picked by [`Solver`](base::config::Solver), per scene, on the command line or at runtime:
//!
//! | solver | what it does |
//! |---|---|
//! | `discrete` | moves, pushes overlapping pairs apart and applies the elastic impulse ([`solvers::discrete`]): the cheapest, but circles overlap and fast pairs tunnel. |
//! | `substeps=N` | runs `discrete` N times a step with dt/N: errors shrink roughly like 1/N while the cost grows like N. |
//! | `swept` | processes each step's pair and wall hits in time order at their times of impact ([`solvers::exact`]), afresh every step: no tunnelling, no overlap. |
//! | `exact` | keeps one event-driven engine (`solvers::exact`'s engine, [`kernels::EventEngine`]) across steps: the reference, exact to rounding, paying per collision rather than per step. |
//! | `soft` | the contact solver for games and piles ([`solvers::soft`]): persistent speculative contacts made soft springs, warm started and solved in 4 substeps (`soft=N`: N) with relaxation and a restitution pass, so stacks and piles rest. |
//!
//! # Modules
//!
//! Seven layers, each importing only from those below it (`docs/architecture.md` has the map,
//! file by file):
//! - [`base`]: what every layer shares: the arena, a circle's state and its components, segment
//!   walls, the configuration ([`CirclesConfig`](base::config::CirclesConfig)) with the limits on every value, hit messages
//!   and counters, errors;
//! - `collision` (internal): the collision layer, free of the ECS: times of impact, roots,
//!   impulses smooth and rough, the broad phase, pair lists, overlap measures;
//! - [`step`]: what every solver's step shares: the [`CircleSystems`] sets and step schedules,
//!   the registry that keeps exactly the effects a scene calls for, gravity and drag, free
//!   flight, walls, periodic edges and segment walls, sleeping;
//! - [`solvers`]: one folder a solver: `discrete` and `substeps=N`, `swept` and `exact` on one
//!   event engine, and the contact solver `soft`;
//! - [`game`]: the plugin group [`CirclesPlugins`], spawning, sensors, spatial queries, each
//!   circle's `Transform` following its position, and the diagnostics (energy, momentum,
//!   pressure);
//! - [`tools`] (feature `tools`, which `cli` and `render` bring): scene and particle files,
//!   the headless app and the one stepping loop, checkpoints, the accuracy study and the
//!   equation of state, files in and out;
//! - [`render`] (feature `render`): the window, sprites, HUD, keys and the live panel;
//! - [`cli`] (feature `cli`): the work behind each `moving_circles` command.
//!
//! [`kernels`] opens the plain-data kernels under the solvers to benchmarks and tests outside
//! the crate; the rest of the collision layer and the solvers' insides are the
//! crate's own.
//!
//! # The guide
//!
//! The repository's `README.md` is the front door; its `docs/` folder holds one page per
//! concern, each figure with the command that made it: `docs/cli.md` (the app, headless runs,
//! scenes, the configuration reference), `docs/cli-reference.md` (every command's options),
//! `docs/solvers.md` (the accuracy study and what to pick), `docs/piles.md` (piles and stacks
//! under gravity), `docs/physics.md`, `docs/embedding.md`, `docs/rollback.md` (rollback
//! netcode), `docs/sweeps.md` (grids of runs, on Slurm too), `docs/robustness.md`,
//! `docs/performance.md`, `docs/architecture.md`, `docs/testing.md` and `docs/history.md`;
//! `benches/README.md` describes the benchmarks.
#![warn(missing_docs)]

// The Rust examples of the README and of the guide's embedding and rollback pages, compiled
// and run as
// doctests (`cargo test --doc`).
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
#[cfg(doctest)]
#[doc = include_str!("../docs/embedding.md")]
struct EmbeddingDoctests;
#[cfg(doctest)]
#[doc = include_str!("../docs/rollback.md")]
struct RollbackDoctests;

pub mod base;
#[cfg(feature = "cli")]
pub mod cli;
mod collision;
pub mod game;
#[cfg(feature = "render")]
pub mod render;
pub mod solvers;
pub mod step;
#[cfg(feature = "tools")]
pub mod tools;

pub use game::plugins::CirclesPlugins;

/// The plain-data kernels under the solvers, public for what measures them from outside the
/// crate (the criterion benches, the system tests) and for a study of your own: the broad
/// phase, the contact and rough impulses, times of impact (under gravity too), the overlap
/// measures, the discrete contact pass and the event engine. They work on plain arrays,
/// without an App. Their signatures follow the solvers' needs and change with them.
pub mod kernels {
    pub use crate::collision::broad_phase::{CellList, overlapping_pairs, visit_overlapping_pairs};
    pub use crate::collision::contact::{
        ContactOutcome, apply_impulse, combine_restitution, resolve_contact, work_by_immovable,
    };
    pub use crate::collision::fall::{exit_time, falling_pair_time};
    pub use crate::collision::overlaps::{Overlaps, overlapping_circles};
    pub use crate::collision::rough::{RoughSide, apply_rough_impulse};
    pub use crate::collision::toi::{
        growing_pair_time_of_impact, pair_time_of_impact, segment_time_of_impact,
    };
    pub use crate::solvers::discrete::pass::{ContactScratch, PassStats, resolve_all_contacts};
    pub use crate::solvers::exact::engine::{
        BudgetExhausted, EngineSnapshot, EventEngine, EventStats, Rest, Roughness,
    };
}

/// The common imports: the plugin group and its parts, components, configuration, sets and
/// what the simulation measures.
pub mod prelude {
    pub use crate::CirclesPlugins;
    pub use crate::base::arena::{Arena, Boundary};
    pub use crate::base::circle::CircleState;
    pub use crate::base::collision_layers::{
        CollisionLayers, OverlapEnded, OverlapStarted, Sensor, SensorOverlaps,
    };
    pub use crate::base::components::{
        AngularVelocity, Friction, Inertia, Mass, Position, Radius, Restitution, Rotation, Sleep,
        Tint, Velocity,
    };
    pub use crate::base::config::{
        CirclesConfig, Combine, DropConfig, Effects, MassModel, Placement, SleepConfig, SoftConfig,
        Solver, SpawnConfig,
    };
    pub use crate::base::hits::PairCollisions;
    pub use crate::base::hits::{ArenaWall, CircleHit, Wall, WallHit};
    pub use crate::base::segment::{Segment, Segments};
    pub use crate::game::diagnostics::{CircleDiagnostics, DiagnosticsPlugin, Measuring};
    pub use crate::game::query::{CastHit, QueryFilter, SpatialQuery, SpatialQueryPlugin, Target};
    pub use crate::game::sensor::SensorPlugin;
    pub use crate::game::spawn::{Respawn, SpawnPlugin, SpawnReport};
    pub use crate::game::transform_sync::{DefaultSmoothing, Smoothing, TransformSyncPlugin};
    pub use crate::solvers::discrete::{CollidePlugin, DiscretePlugin};
    pub use crate::solvers::exact::{ContinuousPlugin, ContinuousStep, EventBudget};
    pub use crate::solvers::soft::{SoftPlugin, SoftStep};
    pub use crate::step::boundary::{PeriodicPlugin, SegmentsPlugin, WallCollisions, WallsPlugin};
    pub use crate::step::effects::Effect;
    pub use crate::step::forces::{DragPlugin, GravityPlugin};
    pub use crate::step::integrate::IntegratePlugin;
    pub use crate::step::schedule::{CircleStep, CircleSystems, StepPlugin, StepTotals};
    pub use crate::step::sleep::{SleepPlugin, Sleeping};
    #[cfg(feature = "tools")]
    pub use crate::tools::scene::Scene;
}

pub use base::components::{
    AngularVelocity, Friction, Inertia, Mass, Position, Radius, Restitution, Rotation, Tint,
    Velocity,
};
pub use step::schedule::CircleSystems;
