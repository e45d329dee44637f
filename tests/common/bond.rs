//! Checks of a model's bond graph: causality on every bond, consistent junctions, integral
//! causality on every storage element, and its states one to one with the model's.

use stirling::dsl::bond::{bond_graph, states, BondGraph, CausalGraph, Kind};
use stirling::dsl::{Model, StateKind};

/// The causal bond graph of `m`, after checking it.
pub fn check(m: &dyn Model) -> CausalGraph {
    let what = format!("{} (n = {}, {})", m.name(), m.n(), m.closure());
    let cg = bond_graph(m).unwrap_or_else(|e| panic!("{what}: {e}"));
    let g = &cg.graph;
    one_stroke_per_bond(g, &what);
    junctions_consistent(g, &what);
    integral_storage(g, &what);
    assert!(
        cg.derivative.is_empty(),
        "{what}: derivative causality {:?}",
        cg.derivative
    );
    states_one_to_one(g, m, &what);
    cg
}

/// Every bond has exactly one causal stroke, at one of its two ends.
pub fn one_stroke_per_bond(g: &BondGraph, what: &str) {
    for (k, b) in g.bonds.iter().enumerate() {
        let e = b
            .effort_to
            .unwrap_or_else(|| panic!("{what}: bond {k} has no stroke"));
        assert!(
            e == b.from || e == b.to,
            "{what}: bond {k} stroke at a third node"
        );
        assert_ne!(b.from, b.to, "{what}: bond {k} is a loop");
    }
}

/// A 0-junction takes its effort from exactly one bond, a 1-junction its flow from exactly
/// one bond (it hands out the effort there), a TF takes the effort on exactly one side.
pub fn junctions_consistent(g: &BondGraph, what: &str) {
    for (n, node) in g.nodes.iter().enumerate() {
        let bonds = g.bonds_at(n);
        let effort_in = bonds
            .iter()
            .filter(|&&b| g.bonds[b].effort_to == Some(n))
            .count();
        let want_in = match node.kind {
            Kind::Zero => 1,
            Kind::One => bonds.len() - 1,
            Kind::Tf => 1,
            _ => continue,
        };
        assert!(
            bonds.len() >= 2,
            "{what}: junction {n} ({}) has {} bond(s)",
            node.label,
            bonds.len()
        );
        assert_eq!(
            effort_in, want_in,
            "{what}: junction {n} ({}) causality",
            node.label
        );
    }
}

/// Sources have their fixed causality, storage integral causality (an `I` takes the effort,
/// a `C` gives it on every port).
pub fn integral_storage(g: &BondGraph, what: &str) {
    for (n, node) in g.nodes.iter().enumerate() {
        let takes_effort = match node.kind {
            Kind::I | Kind::Sf => true,
            Kind::C | Kind::Se | Kind::MSe => false,
            _ => continue,
        };
        for b in g.bonds_at(n) {
            let got = g.bonds[b].effort_to == Some(n);
            assert_eq!(
                got,
                takes_effort,
                "{what}: {} bond {b} causality",
                node.text()
            );
        }
        if node.kind.is_storage() {
            assert!(
                !node.states.is_empty(),
                "{what}: {} stores nothing",
                node.text()
            );
        }
    }
}

/// The graph's independent states are the model's, each once.
pub fn states_one_to_one(g: &BondGraph, m: &dyn Model, what: &str) {
    let mut graph: Vec<StateKind> = states::independent_states(g);
    let mut model: Vec<StateKind> = m.states().iter().map(|s| s.kind).collect();
    assert_eq!(graph.len(), m.n_states(), "{what}: state count");
    let key = |k: &StateKind| format!("{k:?}");
    graph.sort_by_key(key);
    model.sort_by_key(key);
    let mut unique = graph.clone();
    unique.dedup();
    assert_eq!(unique.len(), graph.len(), "{what}: a state held twice");
    assert_eq!(
        graph, model,
        "{what}: the graph's states are not the model's"
    );
}
