//! What every layer shares: the arena, a circle's plain state and its components, segment
//! walls, the grid, the configuration and its checks, the hit messages and counters, errors,
//! value ranges, the order solvers visit circles in and the vector-instruction switch. Nothing here schedules a
//! system or steps a circle.

pub mod arena;
pub mod circle;
pub mod collision_layers;
pub mod components;
pub mod config;
pub mod error;
pub(crate) mod grid;
pub mod hits;
pub(crate) mod lattice;
pub mod order;
pub(crate) mod range;
pub mod segment;
pub mod vector;
