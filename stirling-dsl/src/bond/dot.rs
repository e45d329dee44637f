//! Graphviz DOT of a causal bond graph.
//!
//! Each bond is an edge `from -> to` drawn with a half-arrow (`lvee`) at `to`: positive power
//! flows that way. The causal stroke (`tee`) sits at the end whose node takes the effort as
//! its input. Junctions are drawn `0` and `1`, elements `KIND: label` (`I: mp`, `C: kd`,
//! `R: bd`, `TF: -A`, `Se: Pb`); a CV's multiport `C` field is an ellipse. Colours tell the
//! domain: black mechanical (`F, v`), blue volume (`P, dV/dt`), red heat (`T, Q`), green
//! mass flow (`P, mdot`). A storage element in derivative causality is drawn red.

use std::fmt::Write;

use super::causality::Derivative;
use super::graph::{BondGraph, Domain, Kind};

/// The DOT text of `g`.
pub fn to_dot(g: &BondGraph, derivative: &[Derivative]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "digraph \"{}\" {{", esc(&g.name));
    s.push_str("  rankdir=LR;\n  node [fontname=\"Helvetica\", shape=plaintext];\n");
    s.push_str("  edge [dir=both, arrowtail=none, arrowhead=lvee, arrowsize=0.9];\n");
    for (i, n) in g.nodes.iter().enumerate() {
        let shape = if n.kind == Kind::C && n.states.len() > 1 {
            ", shape=ellipse"
        } else {
            ""
        };
        let red = if derivative.iter().any(|d| d.node == i) {
            ", fontcolor=red"
        } else {
            ""
        };
        let _ = writeln!(
            s,
            "  n{i} [label=\"{}\", tooltip=\"{}\"{shape}{red}];",
            esc(&n.text()),
            esc(&n.label)
        );
    }
    for (k, b) in g.bonds.iter().enumerate() {
        let stroke = if b.effort_to == Some(b.to) {
            "arrowhead=teelvee"
        } else if b.effort_to == Some(b.from) {
            "arrowtail=tee"
        } else {
            "style=dashed"
        };
        let _ = writeln!(
            s,
            "  n{} -> n{} [{stroke}, color={}, tooltip=\"{}: {}\"];",
            b.from,
            b.to,
            colour(b.domain),
            k + 1,
            b.domain.variables()
        );
    }
    s.push_str("}\n");
    s
}

/// The colour of a domain's bonds.
fn colour(d: Domain) -> &'static str {
    match d {
        Domain::Mechanical => "black",
        Domain::Volume => "blue",
        Domain::Heat => "red",
        Domain::MassFlow => "darkgreen",
    }
}

/// `s` with its double quotes and backslashes escaped for a DOT string.
fn esc(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}
