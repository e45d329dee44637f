//! Model construction: everything that turns a name and numbers into a [`crate::dsl::Model`]
//! with its parameter vector - the seed's family, the effects the nominal models leave out
//! (declared as augmented family members), the registry the command line looks models up
//! in, and parameter files, overrides and validation.
//!
//! The crate root re-exports each module (`stirling_models::family`, ...), so either path
//! works.

/// The seed's model family (`schmidt`, `cv1`, `cv2`, `nsection`) on the default engine
/// (declared first: it declares the bases `default_engine` and `nsection_engine` that
/// [`effects`] extends; a base is a `macro_rules!`, visible in textual order).
#[macro_use]
pub mod family;
/// Bounds of parameters from a file, for the fit.
pub mod bounds;
/// Effects the nominal models leave out, as DSL-declared model augmentations.
pub mod effects;
/// Engines declared in `.stirling` files, loaded and compiled at run time.
pub mod files;
/// Causes outside the effect library: truth models for the rig and the self-check only.
pub mod outside;
/// Parameter files, overrides and validation.
pub mod params;
/// The family by name, as the command line uses it.
pub mod registry;
/// Models a user's crate registers, served by name like the family.
pub mod user_models;
