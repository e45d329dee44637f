//! What generated models implement and what the analyses use.

mod dot;
mod error;
mod model;
mod topology_info;

pub use dot::to_dot;
pub use error::ModelError;
pub use model::{BodyInfo, JacSink, Model, ParamInfo, PowerTerms, StateInfo, StateKind};
pub use topology_info::{
    ConductionInfo, FaceInfo, LinkInfo, PortInfo, TopologyInfo, VesselInfo, WallInfo,
};
