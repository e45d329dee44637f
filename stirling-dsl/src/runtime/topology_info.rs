//! A static description of a declared topology, for the bond-graph (DOT) view and docs.

/// A heat port.
#[derive(Clone, Copy, Debug)]
pub struct PortInfo {
    pub name: &'static str,
    /// The wall temperature, as declared.
    pub wall: &'static str,
}

/// A face coupling a vessel to a body.
#[derive(Clone, Copy, Debug)]
pub struct FaceInfo {
    pub body: &'static str,
    /// The coefficient `a`, as declared.
    pub coeff: &'static str,
}

/// A gas vessel: a CV (or array of CVs) or a given-pressure space.
#[derive(Clone, Copy, Debug)]
pub struct VesselInfo {
    pub name: &'static str,
    pub is_cv: bool,
    pub array: bool,
    pub faces: &'static [FaceInfo],
    pub ports: &'static [PortInfo],
}

/// A mass-flow link between two vessels (`from`, `to` as written, e.g. `regen[j]`).
#[derive(Clone, Copy, Debug)]
pub struct LinkInfo {
    pub from: &'static str,
    pub to: &'static str,
    pub resistance: &'static str,
    pub chain: bool,
}

/// A declared topology.
#[derive(Clone, Copy, Debug)]
pub struct TopologyInfo {
    pub name: &'static str,
    pub doc: &'static str,
    pub bodies: &'static [&'static str],
    /// Coupling dampers between bodies, `(a, b)`.
    pub couplings: &'static [(&'static str, &'static str)],
    pub vessels: &'static [VesselInfo],
    pub links: &'static [LinkInfo],
}
