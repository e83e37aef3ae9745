//! What every solver's fixed step shares: the schedule and its sets ([`schedule`]), the circles
//! as plain arrays (`bodies`: one gather from the ECS, one write-back), the
//! registry that schedules only the effects a scene calls for ([`effects`]), forces, the
//! integration of positions, the arena's walls and segment walls ([`boundary`]) and sleeping
//! ([`sleep`]).

pub(crate) mod bodies;
pub mod boundary;
pub mod effects;
pub mod forces;
pub mod integrate;
pub mod schedule;
pub mod sleep;
