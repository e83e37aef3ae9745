//! The solvers, siblings above the step they share: [`discrete`] (the course's method,
//! `discrete` and `substeps=N`: the contact pass after each substep), [`exact`] (`swept` and
//! `exact`, the event engine) and [`soft`] (the contact solver for piles and games).

pub mod discrete;
pub mod exact;
pub mod soft;
