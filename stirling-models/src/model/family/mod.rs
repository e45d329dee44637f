//! The seed's model family (docs/physics.md sections 3-5), declared with `stirling_model!`.

// The bases are `macro_rules!` made by `stirling_model!`, visible in textual order: the
// engine first, then the members that extend it (`#[macro_use]` carries `nsection_engine`
// on to `crate::effects`).
#[macro_use]
pub(crate) mod engine;
#[macro_use]
mod nsection;
mod cv1;
mod cv2;
mod schmidt;

pub use cv1::{Cv1, Cv1Params};
pub use cv2::{Cv2, Cv2Params};
pub use nsection::{NSection, NSectionParams};
pub use schmidt::{Schmidt, SchmidtParams};
