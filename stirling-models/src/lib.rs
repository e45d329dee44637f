//! # stirling-models: the seed family and the analyses
//!
//! - [`family`]: `schmidt`, `cv1`, `cv2`, `nsection` declared with `stirling_model!`
//!   on the default engine of PHYSICS.md section 8.
//! - [`params`]: parameter files, overrides and validation.
//! - [`registry`]: the family by name, as the command line uses it.

pub mod family;
pub mod params;
pub mod plot;
// <analysis mods>
/// Nonlinear simulation, limit cycles, Floquet multipliers and cycle work.
pub mod sim;
/// Linear analysis: equilibrium, poles, the loop broken at a pressure force, margins, locus.
pub mod linear;
pub mod registry;

pub use registry::{build, RegistryError, FAMILY};
pub use stirling_dsl as dsl;
