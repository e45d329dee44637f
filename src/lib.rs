//! stirling facade
pub use stirling_dsl as dsl;
