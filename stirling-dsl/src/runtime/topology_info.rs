//! A static description of a declared topology, for the bond graph ([`crate::bond`]) and docs.

/// A heat port.
#[derive(Clone, Copy, Debug)]
pub struct PortInfo {
    pub name: &'static str,
    /// The wall temperature, as declared.
    pub wall: &'static str,
    /// The declared wall (a thermal mass) the port exchanges heat with, if any.
    pub wall_ref: Option<&'static str>,
}

/// A wall whose temperature is a state (a thermal capacitance), or an array of `n`.
#[derive(Clone, Copy, Debug)]
pub struct WallInfo {
    pub name: &'static str,
    pub array: bool,
    /// The heat capacity, as declared.
    pub capacity: &'static str,
    /// The heat input from outside, as declared (`"0"` without one).
    pub input: &'static str,
}

/// A conduction link `Q = G (T_from - T_to)` between walls or a wall and a fixed temperature
/// (`from`, `to` as written, e.g. `matrix[j]`, `Tk`; `fixed` marks a fixed-temperature end).
#[derive(Clone, Copy, Debug)]
pub struct ConductionInfo {
    pub from: &'static str,
    pub to: &'static str,
    pub conductance: &'static str,
    /// Whether it repeats along the sections (a chain or a per-section link).
    pub chain: bool,
    /// Whether `from` / `to` is a fixed temperature.
    pub fixed: [bool; 2],
}

/// A face coupling a vessel to a body.
#[derive(Clone, Copy, Debug)]
pub struct FaceInfo {
    pub body: &'static str,
    /// The coefficient `a`, as declared.
    pub coeff: &'static str,
    /// A face on a mechanism (docs/physics.md section 12): its `ds/dtheta` as a function of
    /// the flywheel's angle (`ds_piston(theta)`), the modulus of the modulated transformer;
    /// empty for a plain face (a constant `TF`).
    pub modulus: &'static str,
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

/// The mechanical elements of a body, as declared (`"0"` where absent): what the bond graph
/// attaches to the body's 1-junction.
#[derive(Clone, Copy, Debug, Default)]
pub struct BodyElementsInfo {
    /// The moving mass (`I`).
    pub mass: &'static str,
    /// The spring rate (`C`).
    pub spring: &'static str,
    /// The viscous damping (`R`).
    pub damper: &'static str,
    /// The quadratic damping (`R`, force `c v |v|`).
    pub quad_damper: &'static str,
    /// Any further force (`MSe`).
    pub force: &'static str,
}

/// A declared topology.
#[derive(Clone, Copy, Debug, Default)]
pub struct TopologyInfo {
    pub name: &'static str,
    pub doc: &'static str,
    pub bodies: &'static [&'static str],
    /// Coupling dampers between bodies, `(a, b)`.
    pub couplings: &'static [(&'static str, &'static str)],
    pub vessels: &'static [VesselInfo],
    pub links: &'static [LinkInfo],
    /// Walls with a temperature state.
    pub walls: &'static [WallInfo],
    /// Conduction links between walls, or a wall and a fixed temperature.
    pub conductions: &'static [ConductionInfo],
    /// The elements of each body, in body order (for the bond graph); empty when unknown
    /// (the graph then labels them by the body's name).
    pub body_elements: &'static [BodyElementsInfo],
    /// The damping coefficient of each coupling, in coupling order; empty when unknown.
    pub coupling_dampers: &'static [&'static str],
    /// The given pressure of each space (the vessels with `is_cv == false`), in their order;
    /// empty when unknown.
    pub space_pressures: &'static [&'static str],
}
