//! What a game builds on, above the solvers: the plugin group ([`plugins`]), placing circles
//! ([`spawn`]), sensors, spatial queries, each circle's `Transform` following its position
//! ([`transform_sync`]), the measures of the whole simulation ([`diagnostics`]) and its whole
//! state in memory, for rollback ([`rollback`]).

pub mod diagnostics;
pub mod plugins;
pub mod query;
pub mod rollback;
pub mod sensor;
pub mod spawn;
pub mod transform_sync;
