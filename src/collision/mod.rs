//! The collision layer, free of the ECS: kernels over plain values and arrays that every
//! solver, the spatial queries and the placement share. Times of impact along straight lines
//! ([`toi`]) and parabolas ([`fall`], with their quadratic and quartic roots), the impulse of a hit ([`contact`]; rough
//! hits' tangential part in [`rough`]), the broad phase ([`broad_phase`]), pairs kept from step
//! to step (`pair_list`) and overlap measures ([`overlaps`]).

pub mod broad_phase;
pub mod contact;
pub mod fall;
pub mod overlaps;
pub(crate) mod pair_list;
pub(crate) mod roots;
pub mod rough;
pub mod toi;
