//! Construction of the bond graph from a [`TopologyInfo`] at `n` sections and a closure:
//! the mechanical part here (bodies, couplings), the gas in [`super::build_gas`], the heat
//! paths in [`super::build_heat`].

use std::collections::HashSet;

use super::error::BondError;
use super::graph::{BondGraph, Domain, Kind, NodeId, Store};
use crate::runtime::TopologyInfo;
use crate::Closure;

/// Names an expression may use and still be a constant: functions and the section index.
const CONSTANT_NAMES: [&str; 14] = [
    "pi", "sqrt", "ln", "exp", "abs", "tanh", "sin", "cos", "min", "max", "pow", "j", "n", "e",
];

/// One connection of a gas port: the node and whether positive power flows out of the gas.
pub type Conn = (NodeId, bool);

/// The connections of one vessel element, per port.
#[derive(Clone, Debug, Default)]
pub struct Ports {
    /// Face transformers (volume bonds).
    pub volume: Vec<Conn>,
    /// Heat-port 1-junctions.
    pub heat: Vec<Conn>,
    /// Mass-flow link 1-junctions.
    pub mass: Vec<Conn>,
}

/// The graph under construction with what the steps share.
pub struct Builder<'a> {
    pub g: BondGraph,
    pub topo: &'a TopologyInfo,
    pub n: usize,
    pub closure: Closure,
    params: HashSet<&'a str>,
    /// The 1-junction (common velocity) of each body.
    pub bodies: Vec<NodeId>,
    /// The 0-junction (common temperature) of each wall element, per wall.
    pub walls: Vec<Vec<NodeId>>,
    /// The element ports of each vessel (one per section for an array).
    pub vessels: Vec<Vec<Ports>>,
    /// The field node of each CV element per vessel (empty for a space).
    pub fields: Vec<Vec<NodeId>>,
}

/// The bond graph of `topo` at `n` sections and `closure`; `params` are the parameter
/// names (an expression of them alone is a constant source `Se`, else `MSe`).
pub fn build(
    topo: &TopologyInfo,
    n: usize,
    closure: Closure,
    params: &[&str],
) -> Result<BondGraph, BondError> {
    let mut b = Builder {
        g: BondGraph::new(topo.name),
        topo,
        n: n.max(1),
        closure,
        params: params.iter().copied().chain(CONSTANT_NAMES).collect(),
        bodies: Vec::new(),
        walls: Vec::new(),
        vessels: Vec::new(),
        fields: Vec::new(),
    };
    b.bodies();
    b.couplings();
    b.walls();
    b.vessels();
    b.ports()?;
    b.links()?;
    b.conductions()?;
    b.finish();
    Ok(b.g)
}

impl<'a> Builder<'a> {
    /// Elements of an array count `n`, of a scalar 1.
    pub fn count(&self, array: bool) -> usize {
        if array {
            self.n
        } else {
            1
        }
    }

    /// `Se` for an expression of parameters and numbers, `MSe` for one that reads states.
    pub fn effort_source(&mut self, expr: &str) -> NodeId {
        let constant = expr
            .split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .filter(|w| w.starts_with(|c: char| c.is_alphabetic() || c == '_'))
            .all(|w| self.params.contains(w));
        let kind = if constant { Kind::Se } else { Kind::MSe };
        self.g.node(kind, expr)
    }

    /// A 1-junction per body with its mass `I`, spring `C`, dampers `R` and extra force `MSe`.
    fn bodies(&mut self) {
        let topo = self.topo;
        for (k, name) in topo.bodies.iter().enumerate() {
            let one = self.g.node(Kind::One, format!("v {name}"));
            self.bodies.push(one);
            let el = topo.body_elements.get(k);
            let mass = el.map_or(format!("m {name}"), |e| e.mass.to_string());
            let i = self.g.storage(Kind::I, mass, vec![Store::Momentum(k)]);
            self.g.bond(one, i, Domain::Mechanical);
            let spring = el.map_or(format!("k {name}"), |e| e.spring.to_string());
            let c = self
                .g
                .storage(Kind::C, spring, vec![Store::Displacement(k)]);
            self.g.bond(one, c, Domain::Mechanical);
            let Some(e) = el else { continue };
            for (coeff, law) in [(e.damper, ""), (e.quad_damper, " v|v|")] {
                if coeff != "0" {
                    let r = self.g.node(Kind::R, format!("{coeff}{law}"));
                    self.g.bond(one, r, Domain::Mechanical);
                }
            }
            if e.force != "0" {
                let f = self.effort_source(e.force);
                self.g.bond(f, one, Domain::Mechanical);
            }
        }
    }

    /// A coupling damper: a 0-junction (common force) between the two bodies' 1-junctions,
    /// whose flow balance is the relative velocity the `R` sees.
    fn couplings(&mut self) {
        let topo = self.topo;
        for (c, (a, b)) in topo.couplings.iter().enumerate() {
            let [ja, jb] = [a, b].map(|x| topo.bodies.iter().position(|y| y == x));
            let (Some(ja), Some(jb)) = (ja, jb) else {
                continue;
            };
            let zero = self.g.node(Kind::Zero, format!("F {a}-{b}"));
            self.g.bond(self.bodies[ja], zero, Domain::Mechanical);
            self.g.bond(zero, self.bodies[jb], Domain::Mechanical);
            let label = topo
                .coupling_dampers
                .get(c)
                .map_or(format!("b {a}-{b}"), |d| d.to_string());
            let r = self.g.node(Kind::R, label);
            self.g.bond(zero, r, Domain::Mechanical);
        }
    }

    /// Joins `port` (a field or a source) to `conns` in `domain`: directly when there is one,
    /// else through a 0-junction (the common effort) labelled `common`.
    pub fn attach(&mut self, port: NodeId, conns: &[Conn], domain: Domain, common: String) {
        let link = |g: &mut BondGraph, at: NodeId, (c, out): Conn| {
            if out {
                g.bond(at, c, domain);
            } else {
                g.bond(c, at, domain);
            }
        };
        match conns {
            [] => {}
            [one] => link(&mut self.g, port, *one),
            many => {
                let zero = self.g.node(Kind::Zero, common);
                let out = many.iter().filter(|c| c.1).count() * 2 >= many.len();
                link(&mut self.g, port, (zero, out));
                for c in many {
                    link(&mut self.g, zero, *c);
                }
            }
        }
    }
}
