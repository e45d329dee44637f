//! The assembled equations of one topology under one closure.

use crate::expr::Id;
use crate::Closure;

/// Position of a section in an array, which decides the links it has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// `n = 1`: the only section, both array ends.
    Single,
    /// Section 0 of `n >= 2`.
    First,
    /// `0 < j < n - 1`.
    Interior,
    /// Section `n - 1` of `n >= 2`.
    Last,
}

/// All variants, in the order of [`Row::Array`].
pub const VARIANTS: [Variant; 4] = [
    Variant::Single,
    Variant::First,
    Variant::Interior,
    Variant::Last,
];

impl Variant {
    /// Human-readable range of sections.
    pub fn describe(self) -> &'static str {
        match self {
            Variant::Single => "n = 1",
            Variant::First => "j = 0 (n >= 2)",
            Variant::Interior => "0 < j < n-1",
            Variant::Last => "j = n-1 (n >= 2)",
        }
    }
}

/// What a state block holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockKind {
    Position(usize),
    Velocity(usize),
    Pressure(usize),
    Mass(usize),
    /// Temperature of wall `w` (declaration order).
    WallTemperature(usize),
}

/// One state block: a scalar, or `n` states of an array CV.
#[derive(Clone, Debug)]
pub struct BlockInfo {
    /// The block number used in `Sym::State`.
    pub sym: u32,
    pub name: String,
    pub array: bool,
    pub kind: BlockKind,
}

/// The right-hand side of one block: one expression, or one per [`Variant`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Row {
    Scalar(Id),
    Array([Id; 4]),
}

impl Row {
    /// The expressions of the row.
    pub fn ids(&self) -> Vec<Id> {
        match self {
            Row::Scalar(id) => vec![*id],
            Row::Array(v) => v.to_vec(),
        }
    }
}

/// Per-vessel quantities for reductions (work, energy, mass), in the vessel's own frame.
#[derive(Clone, Debug)]
pub struct VesselTerms {
    pub name: String,
    pub array: bool,
    /// A control volume (`true`) or a given-pressure space (`false`).
    pub is_cv: bool,
    pub pressure: Id,
    pub volume: Id,
    /// `P V / (gamma - 1)` for CVs, zero for spaces.
    pub energy: Id,
    /// Heat into the vessel through its ports.
    pub heat: Id,
    /// Power the surroundings put into the system here: for a space `P dV/dt` plus the
    /// enthalpy it sends through links; zero for CVs.
    pub boundary: Id,
    /// Gas mass (state or frozen), zero for spaces.
    pub mass: Id,
    /// Gas temperature (NaN for a space without one).
    pub temperature: Id,
}

/// A wall's share of the energy budget, in its own frame.
#[derive(Clone, Debug)]
pub struct WallTerms {
    pub array: bool,
    /// `C Tw`.
    pub energy: Id,
    /// Heat from outside the system into the wall element: its `input`.
    pub heat: Id,
}

/// The assembled model.
#[derive(Clone, Debug)]
pub struct System {
    pub closure: Closure,
    /// State blocks in state order.
    pub blocks: Vec<BlockInfo>,
    /// Right-hand side per block.
    pub rows: Vec<Row>,
    /// Equilibrium guess per block (docs/physics.md section 6).
    pub init: Vec<Row>,
    /// Pressure force on each body.
    pub forces: Vec<Id>,
    pub vessels: Vec<VesselTerms>,
    /// `sum m v^2/2 + k q^2/2`.
    pub mech_energy: Id,
    /// Power of the dampers, couplings and extra forces (negative when dissipating).
    pub mech_power: Id,
    /// Energy terms of every wall.
    pub walls: Vec<WallTerms>,
    /// Heat from fixed temperatures into walls through conduction links (a scalar sum).
    pub wall_boundary_heat: Id,
    /// The templates (array frame) whose sums over the sections `Sym::Sum(k)` stands for.
    pub sums: Vec<Id>,
    /// Whether each symbol block number is an array block.
    pub array_blocks: Vec<bool>,
}

impl System {
    /// Position of the block with symbol number `sym` in state order.
    pub fn block_index(&self, sym: u32) -> Option<usize> {
        self.blocks.iter().position(|b| b.sym == sym)
    }
}
