//! Model construction: everything that turns a name and numbers into a [`crate::dsl::Model`]
//! with its parameter vector - the seed's family, the effects the nominal models leave out
//! (declared as augmented family members), the registry the command line looks models up
//! in, and parameter files, overrides and validation.
//!
//! The crate root re-exports each module (`stirling_models::family`, ...), so either path
//! works.

/// Effects the nominal models leave out, as DSL-declared model augmentations.
pub mod effects;
/// The seed's model family (`schmidt`, `cv1`, `cv2`, `nsection`) on the default engine.
pub mod family;
/// Parameter files, overrides and validation.
pub mod params;
/// The family by name, as the command line uses it.
pub mod registry;
