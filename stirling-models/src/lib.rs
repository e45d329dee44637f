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
/// Effects the nominal models leave out, as DSL-declared model augmentations.
pub mod effects;
/// Measured data: CSV input with row/column errors, sensor offsets.
pub mod data;
/// The virtual test rig: truth model plus effects, noise, offsets, sample rate.
pub mod rig;
/// Identification: driven subsystems, forward sensitivities, Levenberg-Marquardt, report.
pub mod fit;
/// Nonlinear simulation, limit cycles, Floquet multipliers and cycle work.
pub mod sim;
/// Linear analysis: equilibrium, poles, the loop broken at a pressure force, margins, locus.
pub mod linear;
pub mod registry;

pub use registry::{build, RegistryError, FAMILY};
pub use stirling_dsl as dsl;
