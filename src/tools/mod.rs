//! The tools around the engine: headless runs and their reports ([`run`]), checkpoints,
//! scenes and particle files, the accuracy study, the equation of state and figures. The
//! commands of the `moving_circles` binary that use them are in `crate::cli`.

pub mod accuracy;
pub mod checkpoint;
pub mod eos;
#[cfg(feature = "cli")]
pub(crate) mod figure;
pub mod io;
pub mod run;
pub mod scene;
