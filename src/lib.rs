//! # stirling: energetic, symbolic modeling of free-piston Stirling engines
//!
//! The facade: re-exports the symbolic core ([`dsl`]), the `stirling_model!` macro and
//! the model family with its analyses ([`models`]).

pub use stirling_dsl as dsl;
pub use stirling_macros::stirling_model;
pub use stirling_models as models;
