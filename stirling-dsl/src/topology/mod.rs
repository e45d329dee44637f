//! The topology description and its energetic assembly into equations.

mod assemble;
mod decl;
pub mod frame;
mod system;

pub use assemble::assemble;
pub use decl::{
    BodyDecl, CouplingDecl, CvDecl, End, FaceDecl, GasDecl, LinkDecl, ParamDecl, PortDecl,
    SpaceDecl, Topology, Vessel,
};
pub use system::{BlockInfo, BlockKind, Row, System, Variant, VesselTerms, VARIANTS};
