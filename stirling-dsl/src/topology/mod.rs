//! The topology description and its energetic assembly into equations.

mod assemble;
mod budget;
mod decl;
/// Moving array expressions between frames.
pub mod frame;
mod links;
mod system;
mod walls;

pub use assemble::assemble;
pub use decl::{
    BodyDecl, ConductionDecl, CouplingDecl, CvDecl, End, FaceDecl, GasDecl, HeatEnd, LinkDecl,
    ParamDecl, PortDecl, SpaceDecl, Topology, Vessel, WallDecl,
};
pub use system::{BlockInfo, BlockKind, Row, System, Variant, VesselTerms, WallTerms, VARIANTS};
