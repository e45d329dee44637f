//! A true bond graph of a declared model (docs/bond-graphs.md): 1-junctions for the bodies
//! with their `I`, `C`, `R` and `MSe`; `TF`s for the piston faces; each gas control volume a
//! multiport `C` field (volume, heat and mass ports); 0-junctions where efforts are shared;
//! `R`s for the flow resistances and heat conductances; sources for fixed temperatures and
//! given pressures; walls as thermal `C`s. Causality by the sequential procedure (SCAP).
//!
//! One file per step: [`graph`](crate::bond::graph) the structure, `build*` its
//! construction from a [`crate::TopologyInfo`], [`causality`](crate::bond::causality) the
//! SCAP, [`states`](crate::bond::states) the map onto the model's states, `dot` the Graphviz
//! text, [`layout`](crate::bond::layout) and `svg` a drawing without Graphviz.

mod build;
mod build_gas;
mod build_heat;
pub mod causality;
mod dot;
mod ends;
mod error;
pub mod graph;
pub mod layout;
pub mod states;
mod svg;

pub use causality::Derivative;
pub use error::BondError;
pub use graph::{Bond, BondGraph, Domain, Kind, Node, NodeId, Store};

use crate::runtime::Model;

/// A bond graph with its causality assigned.
#[derive(Clone, Debug, PartialEq)]
pub struct CausalGraph {
    pub graph: BondGraph,
    /// The storage ports left in derivative causality, with their physical meaning.
    pub derivative: Vec<Derivative>,
}

impl CausalGraph {
    /// Graphviz DOT with causal strokes and half-arrows.
    pub fn to_dot(&self) -> String {
        dot::to_dot(&self.graph, &self.derivative)
    }

    /// An SVG drawing (layered layout, no Graphviz needed).
    pub fn to_svg(&self) -> String {
        svg::to_svg(&self.graph, &self.derivative)
    }
}

/// The causal bond graph of `model` at its `n` and closure.
pub fn bond_graph(model: &dyn Model) -> Result<CausalGraph, BondError> {
    let names: Vec<&str> = model.params().iter().map(|p| p.name).collect();
    let mut graph = build::build(model.topology(), model.n(), model.closure(), &names)?;
    let derivative = causality::assign(&mut graph)?;
    Ok(CausalGraph { graph, derivative })
}
