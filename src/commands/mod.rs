//! The work behind each `moving_circles` command, callable without the binary: `main.rs` only
//! turns arguments into these options and reports errors.
//!
//! - [`run`]: a headless run of a scene or particle file, with report and dump;
//! - [`accuracy`]: the accuracy study;
//! - [`eos`]: the hard-disk equation of state;
//! - [`systems`]: the systems a scene schedules;
//! - `app` (feature `render`): the windowed app.

pub mod accuracy;
#[cfg(feature = "render")]
pub mod app;
pub mod eos;
pub mod run;
pub mod systems;
