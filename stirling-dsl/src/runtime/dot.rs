//! The energetic (bond-graph) view of a topology as Graphviz DOT.
//!
//! Bodies are inertias (`I`), gas vessels are capacitances (`C`, a given-pressure
//! space is an effort source `Se`), each face is a transformer (`TF: a`) between a
//! vessel and a body, each heat port a thermal source (`Se: Tw`) with its conduction
//! resistance, each mass-flow link a resistor (`R`), each coupling damper a resistor
//! between bodies.

use std::fmt::Write;

use super::topology_info::TopologyInfo;

/// Graphviz DOT of `t`.
pub fn to_dot(t: &TopologyInfo) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "digraph \"{}\" {{", t.name);
    let _ = writeln!(s, "  rankdir=LR;\n  node [fontname=\"Helvetica\"];");
    for b in t.bodies {
        let _ = writeln!(
            s,
            "  \"body:{b}\" [shape=box, style=bold, label=\"I: {b}\"];"
        );
    }
    for (a, b) in t.couplings {
        let _ = writeln!(s, "  \"R:{a}-{b}\" [shape=plaintext, label=\"R: damper\"];");
        let _ = writeln!(
            s,
            "  \"body:{a}\" -> \"R:{a}-{b}\" -> \"body:{b}\" [arrowhead=halfopen];"
        );
    }
    for v in t.vessels {
        vessel(&mut s, v);
    }
    for l in t.links {
        link(&mut s, l);
    }
    s.push_str("}\n");
    s
}

/// A mass-flow link: a resistor between the two vessels it joins.
fn link(s: &mut String, l: &super::topology_info::LinkInfo) {
    let id = format!("R:{}->{}", l.from, l.to);
    let label = if l.chain {
        format!("R: {} (each j)", l.resistance)
    } else {
        format!("R: {}", l.resistance)
    };
    let _ = writeln!(
        s,
        "  \"{id}\" [shape=plaintext, label=\"{}\"];",
        esc(&label)
    );
    let (from, to) = (base(l.from), base(l.to));
    let _ = writeln!(
        s,
        "  \"gas:{from}\" -> \"{id}\" -> \"gas:{to}\" [arrowhead=halfopen, label=\"mdot, H\"];"
    );
}

/// A vessel (capacitance or effort source) with its faces and heat ports.
fn vessel(s: &mut String, v: &super::topology_info::VesselInfo) {
    let kind = if v.is_cv { "C" } else { "Se" };
    let label = if v.array {
        format!("{kind}: {}[j], j < n", v.name)
    } else {
        format!("{kind}: {}", v.name)
    };
    let shape = if v.is_cv { "ellipse" } else { "box" };
    let _ = writeln!(
        s,
        "  \"gas:{}\" [shape={shape}, label=\"{}\"];",
        v.name,
        esc(&label)
    );
    for f in v.faces {
        let id = format!("TF:{}-{}", v.name, f.body);
        let _ = writeln!(
            s,
            "  \"{id}\" [shape=plaintext, label=\"TF: {}\"];",
            esc(f.coeff)
        );
        let _ = writeln!(
            s,
            "  \"gas:{}\" -> \"{id}\" -> \"body:{}\" [arrowhead=halfopen, label=\"P, dV/dt\"];",
            v.name, f.body
        );
    }
    for p in v.ports {
        let id = format!("Se:{}.{}", v.name, p.name);
        let _ = writeln!(
            s,
            "  \"{id}\" [shape=plaintext, label=\"Se: Tw = {}\"];",
            esc(p.wall)
        );
        let _ = writeln!(
            s,
            "  \"{id}\" -> \"gas:{}\" [arrowhead=halfopen, label=\"Q: {}\"];",
            v.name, p.name
        );
    }
}

/// A link end without its index (`h[j]` -> `h`).
fn base(end: &str) -> &str {
    end.split('[').next().unwrap_or(end)
}

/// `s` with its double quotes escaped for a DOT string.
fn esc(s: &str) -> String {
    s.replace('"', "\\\"")
}
