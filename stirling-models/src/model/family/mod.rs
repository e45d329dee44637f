//! The seed's model family (docs/physics.md sections 3-5), declared with `stirling_model!`.

mod cv1;
mod cv2;
pub(crate) mod engine;
mod nsection;
mod schmidt;

pub use cv1::{Cv1, Cv1Params};
pub use cv2::{Cv2, Cv2Params};
pub use nsection::{NSection, NSectionParams};
pub use schmidt::{Schmidt, SchmidtParams};
