//! The topology description: what a `stirling_model!` declares, with every
//! coefficient already an expression in one shared [`Arena`].
//!
//! Symbols used by the expressions: [`Sym::Param`] for parameters, the body position and velocity
//! blocks (`Sym::State(block, At::Scalar)`, numbered as
//! [`Topology::pos_block`](crate::topology::decl::Topology::pos_block) and
//! [`Topology::vel_block`](crate::topology::decl::Topology::vel_block) give), [`Sym::Index`] and
//! [`Sym::Count`] inside arrays.

use crate::expr::{Arena, At, Id};

/// One model parameter.
#[derive(Clone, Debug)]
pub struct ParamDecl {
    pub name: String,
    pub default: f64,
    pub unit: String,
    pub doc: String,
    /// The range a fit keeps it in (`kd: 650.0 "N/m" in 100.0..2000.0`).
    pub bounds: Option<(f64, f64)>,
}

/// Gas properties shared by all control volumes.
#[derive(Clone, Debug)]
pub struct GasDecl {
    /// Specific gas constant `R`.
    pub r: Id,
    /// Heat-capacity ratio `gamma`.
    pub gamma: Id,
    /// Charge (mean) pressure: every CV's pressure at rest.
    pub charge: Id,
    /// Smoothing scale of the upwind switch `mdot_eps`.
    pub mdot_eps: Id,
}

/// A rigid body on one axis: `m q'' = F_faces + force - k q - c q' - cq q'|q'| - couplings`.
#[derive(Clone, Debug)]
pub struct BodyDecl {
    pub name: String,
    pub pos: String,
    pub vel: String,
    pub mass: Id,
    pub spring: Id,
    pub damper: Id,
    pub quad_damper: Id,
    /// Any further force (a load, friction, an end stop), an expression of states and parameters.
    pub force: Id,
    /// A flywheel (`flywheel wheel(theta, omega) { .. }`): the position is an angle (rad),
    /// the mass an inertia (kg m^2) and the forces torques (docs/physics.md section 12).
    pub rotary: bool,
}

/// A mechanism (docs/physics.md section 12): a position `s(theta)` driven by the angle of a
/// flywheel, a slider-crank (`crank piston(y) on wheel { radius, rod, phase }`) or any
/// expression of the angle (`linkage displacer(x) on wheel { position: .. }`). A face on it
/// changes a volume by `a s(theta)` and puts the torque `a P ds/dtheta` on the flywheel: a
/// modulated transformer.
#[derive(Clone, Debug)]
pub struct MechanismDecl {
    pub name: String,
    /// The position's name (`y`), usable in expressions as `s(theta)`.
    pub pos: String,
    /// `crank` or `linkage`, as declared.
    pub kind: String,
    /// The flywheel (a body with `rotary`) whose angle drives it.
    pub body: usize,
    /// `s(theta)`.
    pub position: Id,
    /// `ds/dtheta`, the transformer's modulus.
    pub ratio: Id,
}

/// A damper between two bodies: force `c (v_b - v_a)` on `a` and the opposite on `b`.
#[derive(Clone, Debug)]
pub struct CouplingDecl {
    pub a: usize,
    pub b: usize,
    pub damper: Id,
}

/// A piston face: the volume changes by `coeff * q_body`, the body feels `coeff * P`.
#[derive(Clone, Debug)]
pub struct FaceDecl {
    pub body: usize,
    pub coeff: Id,
    /// A face on a mechanism ([`MechanismDecl`]): `body` is its flywheel and the volume
    /// changes by `coeff * s(theta)`, not `coeff * q_body`.
    pub mechanism: Option<usize>,
}

/// A heat port: `Q = h area (wall - T)`.
#[derive(Clone, Debug)]
pub struct PortDecl {
    pub name: String,
    pub h: Id,
    pub area: Id,
    /// The wall temperature: an expression, or the state symbol of a declared wall.
    pub wall: Id,
    /// The declared [`WallDecl`] the port exchanges heat with (`None`: a fixed temperature).
    pub wall_ref: Option<usize>,
}

/// A solid wall whose temperature `Tw` is a state (a thermal mass), or an array of `n`:
/// `C Tw' = input - sum(port heat into the gas) + sum(conduction into the wall)`.
#[derive(Clone, Debug)]
pub struct WallDecl {
    pub name: String,
    pub array: bool,
    /// Heat capacity `C` (J/K); may use `Index`/`Count` in an array.
    pub capacity: Id,
    /// Temperature at rest, the equilibrium guess (docs/physics.md section 6).
    pub rest: Id,
    /// Heat input from outside the system (a heater), zero if not declared.
    pub input: Id,
}

/// An end of a conduction link: an element of a declared wall, or a fixed temperature.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeatEnd {
    /// `End::vessel` is a [`Vessel::Wall`].
    Wall(End),
    /// A given temperature (an expression of parameters).
    Fixed(Id),
}

/// Conduction `Q = G (T_from - T_to)` from `from` to `to`; a chain (`Rel` ends) repeats
/// for `j in 0..n-1`.
#[derive(Clone, Debug)]
pub struct ConductionDecl {
    pub from: HeatEnd,
    pub to: HeatEnd,
    pub conductance: Id,
}

impl ConductionDecl {
    /// The `Rel` offsets of the wall ends (`0` for other ends).
    pub fn rel(&self) -> [Option<i32>; 2] {
        [self.from, self.to].map(|e| match e {
            HeatEnd::Wall(End { at: At::Rel(r), .. }) => Some(r),
            _ => None,
        })
    }

    /// Whether the link repeats along an array.
    pub fn is_chain(&self) -> bool {
        self.rel().iter().any(Option::is_some)
    }

    /// Whether the link joins every section of a wall array to one wall or fixed temperature
    /// (`link matrix[j] -> shell for j in 0..n`).
    pub fn is_per_section(&self) -> bool {
        let [a, b] = self.rel();
        a.is_some() != b.is_some()
    }
}

/// A space whose pressure is given (a fixed bounce space, or an algebraic pressure such as
/// Schmidt's). It contributes forces through its faces and boundary work `P dV/dt`.
#[derive(Clone, Debug)]
pub struct SpaceDecl {
    pub name: String,
    pub pressure: Id,
    pub volume: Id,
    /// Gas temperature, required only if a mass-flow link touches the space.
    pub temperature: Option<Id>,
    pub faces: Vec<FaceDecl>,
}

/// A gas control volume, or an array of `n` of them (`array`).
#[derive(Clone, Debug)]
pub struct CvDecl {
    pub name: String,
    pub array: bool,
    /// Volume at rest, `V_0` (may use `Index`/`Count` in an array).
    pub volume: Id,
    pub faces: Vec<FaceDecl>,
    pub ports: Vec<PortDecl>,
}

/// What a link end names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Vessel {
    Cv(usize),
    Space(usize),
    /// A declared wall (an end of a conduction link only).
    Wall(usize),
}

/// A link end: the vessel and, for arrays, which element.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct End {
    pub vessel: Vessel,
    pub at: At,
}

/// A mass-flow link `from -> to`: `dP = R mdot + Rq mdot |mdot|` (or `mdot = G dP`), carrying
/// upwind enthalpy. A chain link (`from`/`to` at `Rel` offsets) repeats for `j in 0..n-1`.
#[derive(Clone, Debug)]
pub struct LinkDecl {
    pub from: End,
    pub to: End,
    pub resistance: Id,
    /// Quadratic (turbulent) coefficient `Rq`, if declared.
    pub quadratic: Option<Id>,
    /// Conductance `G`, if the link was declared with `conductance:` instead of
    /// `resistance:`: the flow law is then `mdot = G dP` (exactly zero at `G = 0`, e.g. a
    /// seal leak at its null value) and `resistance` holds `1/G` for display only.
    pub conductance: Option<Id>,
    /// `(C, dP0)` if declared with `orifice: C, dp0: dP0`: the flow law is then the
    /// regularized square-root law `mdot = C dP / (dP^2 + dP0^2)^(1/4)` (`C sign(dP)
    /// sqrt|dP|` for `|dP| >> dP0`, `C dP / sqrt(dP0)` below), and `resistance` holds the
    /// small-`dP` resistance `sqrt(dP0)/C` for display only.
    pub orifice: Option<(Id, Id)>,
}

impl LinkDecl {
    /// Whether the link repeats along an array between neighbouring sections.
    pub fn is_chain(&self) -> bool {
        matches!(self.from.at, At::Rel(_)) && matches!(self.to.at, At::Rel(_))
    }

    /// Whether the link joins every section of an array to one scalar CV or space
    /// (`link regen[j] -> bounce for j in 0..n`).
    pub fn is_per_section(&self) -> bool {
        matches!(self.from.at, At::Rel(_)) != matches!(self.to.at, At::Rel(_))
    }
}

/// An effect applied where the model names it (`effect coulomb on piston;`), at its null.
#[derive(Clone, Debug)]
pub struct EffectSiteDecl {
    /// The effect (`coulomb`, `end_stops`, `leak`).
    pub effect: String,
    /// Where it acts, as written (`piston`, `cold -> bounce`).
    pub at: String,
    /// Its parameters, the strength first.
    pub params: Vec<String>,
}

/// A measured channel: a CSV column observing one state, or an expression of states and
/// parameters.
#[derive(Clone, Debug)]
pub struct SensorDecl {
    /// The channel (the CSV column's name).
    pub name: String,
    /// The observed state's name as `Model::states` lists it (`x`, `P_cold`, `Tw_matrix[3]`);
    /// empty for an expression sensor.
    pub state: String,
    pub unit: String,
    /// An expression sensor's output (`sensor dp: P_cold - P_bounce "Pa";`).
    pub expr: Option<SensorExpr>,
}

/// The output of an expression sensor: `value` in the arena, whose leaves are
/// `Sym::Input(i)` for the state `reads[i]` and `Sym::Param(k)`.
#[derive(Clone, Debug)]
pub struct SensorExpr {
    pub value: Id,
    /// The states read, as `Model::states` names them, in input order.
    pub reads: Vec<String>,
}

/// A whole declared model.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    pub name: String,
    pub doc: String,
    pub arena: Arena,
    pub params: Vec<ParamDecl>,
    pub gas: Option<GasDecl>,
    pub bodies: Vec<BodyDecl>,
    /// Positions driven by a flywheel's angle (no state of their own).
    pub mechanisms: Vec<MechanismDecl>,
    pub couplings: Vec<CouplingDecl>,
    pub spaces: Vec<SpaceDecl>,
    pub cvs: Vec<CvDecl>,
    pub links: Vec<LinkDecl>,
    pub walls: Vec<WallDecl>,
    pub conductions: Vec<ConductionDecl>,
    pub sensors: Vec<SensorDecl>,
    /// The parameters a fit frees by default (`free a, b;`).
    pub free: Vec<String>,
    /// The effects applied by `effect` items.
    pub effects: Vec<EffectSiteDecl>,
}

impl Topology {
    /// Block number of body `k`'s position.
    pub fn pos_block(k: usize) -> u32 {
        2 * k as u32
    }

    /// Block number of body `k`'s velocity.
    pub fn vel_block(k: usize) -> u32 {
        2 * k as u32 + 1
    }

    /// Block number of wall `w` in a topology of `bodies` bodies and `cvs` CVs (after the
    /// bodies' positions and velocities, the CV pressures and the CV masses).
    pub fn wall_block(bodies: usize, cvs: usize, w: usize) -> u32 {
        (2 * bodies + 2 * cvs + w) as u32
    }

    /// Whether CV `i` takes part in a mass-flow link.
    pub fn cv_is_linked(&self, i: usize) -> bool {
        self.links
            .iter()
            .any(|l| l.from.vessel == Vessel::Cv(i) || l.to.vessel == Vessel::Cv(i))
    }

    /// Whether any CV or wall is an array.
    pub fn has_array(&self) -> bool {
        self.cvs.iter().any(|c| c.array) || self.walls.iter().any(|w| w.array)
    }
}
