//! The first, pseudo bond-graph view of a topology as Graphviz DOT (no junctions, no
//! causality), kept for the Python binding (`stirling-py`), which draws it from the
//! `TopologyInfo` alone. The true bond graph is [`crate::bond::bond_graph`].
//!
//! Bodies are inertias (`I`), gas vessels are capacitances (`C`, a given-pressure
//! space is an effort source `Se`), each face is a transformer (`TF: a`) between a
//! vessel and a body, each heat port a thermal source (`Se: Tw`) with its conduction
//! resistance, each mass-flow link a resistor (`R`), each coupling damper a resistor
//! between bodies. A wall with a temperature state is a thermal capacitance (`C: Tw`, with
//! its heat input a flow source `Sf`), a port to it a heat-flow bond from the wall to the
//! gas, and a conduction link a thermal resistor (`R: 1/G`) between two walls or a wall and
//! a fixed temperature (`Se: T`).

use std::fmt::Write;

use super::topology_info::TopologyInfo;

/// Graphviz DOT of the pseudo bond graph of `t` (see [`crate::bond::bond_graph`] for the
/// true one, with junctions and causality).
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
    for w in t.walls {
        wall(&mut s, w);
    }
    for c in t.conductions {
        conduction(&mut s, c);
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
        if let Some(w) = p.wall_ref {
            // a port to a declared wall: heat from the wall's capacitance into the gas
            let each = if v.array { " (each j)" } else { "" };
            let _ = writeln!(
                s,
                "  \"wall:{w}\" -> \"gas:{}\" [arrowhead=halfopen, label=\"Q: {}{each}\"];",
                v.name, p.name
            );
            continue;
        }
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

/// A wall: a thermal capacitance, with its heat input as a flow source.
fn wall(s: &mut String, w: &super::topology_info::WallInfo) {
    let label = if w.array {
        format!("C: {}[j], j < n (capacity {})", w.name, w.capacity)
    } else {
        format!("C: {} (capacity {})", w.name, w.capacity)
    };
    let _ = writeln!(
        s,
        "  \"wall:{}\" [shape=ellipse, style=dashed, label=\"{}\"];",
        w.name,
        esc(&label)
    );
    if w.input != "0" {
        let id = format!("Sf:{}", w.name);
        let _ = writeln!(
            s,
            "  \"{id}\" [shape=plaintext, label=\"Sf: {}\"];",
            esc(w.input)
        );
        let _ = writeln!(
            s,
            "  \"{id}\" -> \"wall:{}\" [arrowhead=halfopen, label=\"Q\"];",
            w.name
        );
    }
}

/// A conduction link: a thermal resistor between two walls or a wall and a fixed temperature.
fn conduction(s: &mut String, c: &super::topology_info::ConductionInfo) {
    let id = format!("Rth:{}->{}", c.from, c.to);
    let each = if c.chain { " (each j)" } else { "" };
    let label = format!("R: 1/({}){each}", c.conductance);
    let _ = writeln!(
        s,
        "  \"{}\" [shape=plaintext, label=\"{}\"];",
        esc(&id),
        esc(&label)
    );
    let mut ends = [c.from, c.to].map(|e| format!("wall:{}", base(e)));
    for (k, fixed) in c.fixed.iter().enumerate() {
        if *fixed {
            let t = [c.from, c.to][k];
            ends[k] = format!("Se:T={t}");
            let _ = writeln!(
                s,
                "  \"{}\" [shape=plaintext, label=\"Se: {}\"];",
                esc(&ends[k]),
                esc(t)
            );
        }
    }
    let _ = writeln!(
        s,
        "  \"{}\" -> \"{}\" -> \"{}\" [arrowhead=halfopen, label=\"Q\"];",
        esc(&ends[0]),
        esc(&id),
        esc(&ends[1])
    );
}

/// A link end without its index (`h[j]` -> `h`).
fn base(end: &str) -> &str {
    end.split('[').next().unwrap_or(end)
}

/// `s` with its double quotes escaped for a DOT string.
fn esc(s: &str) -> String {
    s.replace('"', "\\\"")
}
