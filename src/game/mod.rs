//! What a game builds on, above the solvers: the plugin group ([`plugins`]), placing circles
//! ([`spawn`]), sensors, spatial queries, each circle's `Transform` following its position
//! ([`transform_sync`]) and the measures of the whole simulation ([`diagnostics`]).

pub mod diagnostics;
pub mod plugins;
pub mod query;
pub mod sensor;
pub mod spawn;
pub mod transform_sync;
