//! The integration tests, one module per subject, built as one test binary: one link of Bevy
//! instead of one per file, and every test of the suite run in parallel with the others.
//! Run one subject with `cargo test --test suite SUBJECT::` (for example `galton::`).

mod common;

mod accuracy;
mod app_controls;
mod bad_input;
mod bodies;
mod circle_order;
mod cli;
mod collision_layers;
mod collisions;
mod dense;
mod docs_links;
mod docs_pages;
mod docs_reference;
mod drops;
mod effects;
mod eos;
mod event_reference;
mod exact_promises;
mod friction;
mod galton;
mod game_changes;
mod gravity;
mod hard_cases;
mod hits;
mod hostile;
mod hostile_two;
mod layers;
mod motion;
mod open_arena;
mod outputs;
mod pack;
mod panel;
mod piles;
mod pinned;
mod properties;
mod queries;
mod resume;
mod rollback;
#[cfg(feature = "ggrs")]
mod rollback_ggrs;
mod rough;
mod scenes;
mod schedule;
mod segments;
mod sensors;
mod signals;
mod sleep;
mod soft_promises;
mod solvers;
mod spawn;
mod sweep;
mod transform_sync;
