//! # stirling-models: the seed family and the analyses
pub mod family;
pub use stirling_dsl as dsl;
