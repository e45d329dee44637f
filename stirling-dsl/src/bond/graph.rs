//! The bond-graph structure: elements, junctions and bonds with their causality.

/// Index of a node in [`BondGraph::nodes`].
pub type NodeId = usize;

/// What a node is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A 0-junction: common effort, flows sum to zero.
    Zero,
    /// A 1-junction: common flow, efforts sum to zero.
    One,
    /// A transformer (a piston face: `F = a P`, `dV/dt = a v`).
    Tf,
    /// A modulated transformer (a face on a mechanism: `T = a ds/dtheta P`,
    /// `dV/dt = a ds/dtheta omega`, the modulus a function of the flywheel's angle).
    Mtf,
    /// An inertia (a body's mass).
    I,
    /// A capacitance: a spring, a wall's heat capacity, or a gas control volume's multiport
    /// field (see [`Store`]).
    C,
    /// A resistor (damper, flow resistance, heat conductance).
    R,
    /// An effort source of constant effort.
    Se,
    /// A modulated effort source (its effort depends on the states).
    MSe,
    /// A flow source (a wall's heat input).
    Sf,
}

impl Kind {
    /// The label's prefix: `0`, `1`, `TF`, `MTF`, `I`, `C`, `R`, `Se`, `MSe`, `Sf`.
    pub fn symbol(self) -> &'static str {
        match self {
            Kind::Zero => "0",
            Kind::One => "1",
            Kind::Tf => "TF",
            Kind::Mtf => "MTF",
            Kind::I => "I",
            Kind::C => "C",
            Kind::R => "R",
            Kind::Se => "Se",
            Kind::MSe => "MSe",
            Kind::Sf => "Sf",
        }
    }

    /// Whether the node stores energy (I, C).
    pub fn is_storage(self) -> bool {
        matches!(self, Kind::I | Kind::C)
    }
}

/// A node: a junction or an element.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub kind: Kind,
    /// What follows `KIND: ` in the label (a parameter or an expression as declared); for a
    /// junction, what its common variable is (`v piston`, `P hot`, `T hot`).
    pub label: String,
    /// The states it stores (a storage element; empty otherwise).
    pub states: Vec<Store>,
}

impl Node {
    /// The label as drawn: `0`, `1`, `I: md`, `TF: -A`.
    pub fn text(&self) -> String {
        match self.kind {
            Kind::Zero | Kind::One => self.kind.symbol().to_string(),
            k => format!("{}: {}", k.symbol(), self.label),
        }
    }
}

/// The energy domain of a bond: what its effort and flow are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Force `F` and velocity `v`.
    Mechanical,
    /// Pressure `P` and volume flow `dV/dt`.
    Volume,
    /// Pseudo-bond: temperature `T` and heat flow `Q` (power is `Q`, not `T Q`).
    Heat,
    /// Pseudo-bond: pressure `P` and mass flow `mdot`, carrying the enthalpy `h mdot`.
    MassFlow,
}

impl Domain {
    /// `effort, flow` as drawn on the bond.
    pub fn variables(self) -> &'static str {
        match self {
            Domain::Mechanical => "F, v",
            Domain::Volume => "P, dV/dt",
            Domain::Heat => "T, Q",
            Domain::MassFlow => "P, mdot",
        }
    }
}

/// A state a storage element holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Store {
    /// The momentum `p = m v` of body `k` (an `I`).
    Momentum(usize),
    /// The displacement `q` of body `k` (its spring `C`).
    Displacement(usize),
    /// The volume of CV element `k` (integrated through the field's mechanical port): not
    /// independent, the faces fix it, `V = V0 + sum a q` (see [`super::states`]).
    Volume(usize),
    /// The internal energy `U = P V/(gamma-1)` of CV element `k` (what all its ports change).
    Energy(usize),
    /// The gas mass of CV element `k` (through its mass port, when its mass is a state).
    Mass(usize),
    /// The heat stored in wall element `k`, `C Tw` (a thermal `C`).
    WallHeat(usize),
}

/// A bond `from -> to`: the half-arrow (positive power) points at `to`.
#[derive(Clone, Debug, PartialEq)]
pub struct Bond {
    pub from: NodeId,
    pub to: NodeId,
    pub domain: Domain,
    /// The end whose node takes the effort as its input (the causal stroke's end), once
    /// causality is assigned; the other end's node takes the flow.
    pub effort_to: Option<NodeId>,
}

impl Bond {
    /// The end of the bond that is not `n`.
    pub fn other(&self, n: NodeId) -> NodeId {
        if self.from == n {
            self.to
        } else {
            self.from
        }
    }
}

/// A bond graph.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BondGraph {
    pub name: String,
    pub nodes: Vec<Node>,
    pub bonds: Vec<Bond>,
}

impl BondGraph {
    /// An empty graph called `name`.
    pub fn new(name: &str) -> Self {
        BondGraph {
            name: name.to_string(),
            ..Default::default()
        }
    }

    /// Adds a node.
    pub fn node(&mut self, kind: Kind, label: impl Into<String>) -> NodeId {
        self.nodes.push(Node {
            kind,
            label: label.into(),
            states: Vec::new(),
        });
        self.nodes.len() - 1
    }

    /// Adds a bond `from -> to` (power positive towards `to`).
    pub fn bond(&mut self, from: NodeId, to: NodeId, domain: Domain) -> usize {
        self.bonds.push(Bond {
            from,
            to,
            domain,
            effort_to: None,
        });
        self.bonds.len() - 1
    }

    /// Adds a storage element holding `states`.
    pub fn storage(&mut self, kind: Kind, label: impl Into<String>, states: Vec<Store>) -> NodeId {
        let n = self.node(kind, label);
        self.nodes[n].states = states;
        n
    }

    /// The bonds at node `n`.
    pub fn bonds_at(&self, n: NodeId) -> Vec<usize> {
        (0..self.bonds.len())
            .filter(|&b| self.bonds[b].from == n || self.bonds[b].to == n)
            .collect()
    }

    /// Every state of the storage elements, with the node holding it.
    pub fn states(&self) -> impl Iterator<Item = (NodeId, Store)> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .flat_map(|(i, n)| n.states.iter().map(move |s| (i, *s)))
    }
}
