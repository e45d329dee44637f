//! The topology description and its energetic assembly into equations.

mod assemble;
mod balance;
mod budget;
mod cv;
mod decl;
/// Moving array expressions between frames.
pub mod frame;
mod links;
mod mechanics;
mod system;
mod walls;

pub use assemble::assemble;
pub use decl::{
    BodyDecl, ConductionDecl, CouplingDecl, CvDecl, EffectSiteDecl, End, FaceDecl, GasDecl,
    HeatEnd, LinkDecl, MechanismDecl, ParamDecl, PortDecl, SensorDecl, SensorExpr, SpaceDecl,
    Topology, Vessel, WallDecl,
};
pub use system::{BlockInfo, BlockKind, Row, System, Variant, VesselTerms, WallTerms, VARIANTS};
