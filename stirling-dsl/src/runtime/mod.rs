//! What generated models implement and what the analyses use.

mod error;
mod jac_sink;
mod model;
mod observe;
mod topology_info;

pub use error::ModelError;
pub use jac_sink::{JacSink, JacValues, JacWrite};
pub use model::{
    BodyInfo, EffectSite, Model, ParamInfo, PowerTerms, SensorInfo, StateInfo, StateKind,
};
pub use observe::{Observation, ObserveError};
pub use topology_info::{
    BodyElementsInfo, ConductionInfo, FaceInfo, LinkInfo, PortInfo, TopologyInfo, VesselInfo,
    WallInfo,
};
