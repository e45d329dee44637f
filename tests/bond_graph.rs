//! The true bond graph (docs/bond-graphs.md) of every family member, the effect models and
//! the wall models: junction structure, one causal stroke per bond, consistent junctions,
//! integral causality everywhere (no derivative causality), and its states one to one with
//! the generated model's. The SCAP itself on small graphs with a known answer: two rigidly
//! joined masses (derivative causality) and two sources on one 0-junction (a conflict).

mod common;
#[path = "dsl_walls/models.rs"]
mod walls;

use common::bond::check;
use stirling::dsl::bond::{causality, BondError, BondGraph, Domain, Kind, Store};
use stirling::dsl::{Closure, Model};
use stirling::models::build;
use stirling::models::effects::{Cv1Fx, NSectionExtFx, NSectionFx};

/// Number of nodes of `kind` in the graph of `m`.
fn count(m: &dyn Model, kind: Kind) -> usize {
    let g = check(m).graph;
    g.nodes.iter().filter(|n| n.kind == kind).count()
}

#[test]
fn every_family_member_has_a_consistent_integral_bond_graph() {
    for closure in [Closure::Full, Closure::Frozen] {
        for (name, n) in [("schmidt", None), ("cv1", None), ("cv2", None)] {
            check(build(name, n, closure).unwrap().as_ref());
        }
        for n in [1, 2, 10] {
            check(build("nsection", Some(n), closure).unwrap().as_ref());
        }
    }
}

#[test]
fn the_effect_and_wall_models_have_consistent_integral_bond_graphs() {
    for closure in [Closure::Full, Closure::Frozen] {
        check(&Cv1Fx::new(1, closure).unwrap());
        for n in [1, 2, 10] {
            check(&NSectionFx::new(n, closure).unwrap());
            check(&NSectionExtFx::new(n, closure).unwrap());
            check(&walls::HeadMatrix::new(n, closure).unwrap());
            check(&walls::MatrixShell::new(n, closure).unwrap());
        }
    }
}

/// `cv1`: two bodies (1-junctions), one coupling (a 0-junction), the gas field with its
/// volume 0-junction (common pressure, faces of both bodies) and thermal 0-junction (three
/// heat ports), the bounce space's 0-junction; three TFs for the gas faces and two for the
/// bounce space's.
#[test]
fn cv1_junction_structure() {
    let m = build("cv1", None, Closure::Full).unwrap();
    assert_eq!(count(m.as_ref(), Kind::One), 2 + 3);
    assert_eq!(count(m.as_ref(), Kind::Zero), 1 + 2 + 1);
    assert_eq!(count(m.as_ref(), Kind::Tf), 4);
    assert_eq!(count(m.as_ref(), Kind::I), 2);
    // two springs and the gas field
    assert_eq!(count(m.as_ref(), Kind::C), 3);
    // two dampers, two quadratic dampers, the coupling, three heat conductances
    assert_eq!(count(m.as_ref(), Kind::R), 8);
}

/// `nsection` at n sections: n + 2 fields, n + 1 link resistances, each field a mass port.
#[test]
fn nsection_has_a_field_per_section_and_a_resistance_per_link() {
    for n in [1, 2, 10] {
        let m = build("nsection", Some(n), Closure::Full).unwrap();
        let g = check(m.as_ref()).graph;
        let fields = g
            .nodes
            .iter()
            .filter(|x| x.kind == Kind::C && x.states.len() > 1);
        assert_eq!(fields.count(), n + 2, "n = {n}");
        let links = g
            .nodes
            .iter()
            .filter(|x| x.kind == Kind::One && x.label.starts_with("mdot"));
        assert_eq!(links.count(), n + 1, "n = {n}");
        let masses = g.states().filter(|(_, s)| matches!(s, Store::Mass(_)));
        assert_eq!(masses.count(), n + 2, "n = {n}");
    }
}

/// Two masses on one 1-junction (a rigid joint) pushed by a source: the second mass is in
/// derivative causality, its momentum no state.
#[test]
fn rigidly_joined_masses_give_derivative_causality() {
    let mut g = BondGraph::new("rigid");
    let one = g.node(Kind::One, "v");
    let se = g.node(Kind::Se, "F");
    let i1 = g.storage(Kind::I, "m1", vec![Store::Momentum(0)]);
    let i2 = g.storage(Kind::I, "m2", vec![Store::Momentum(1)]);
    g.bond(se, one, Domain::Mechanical);
    g.bond(one, i1, Domain::Mechanical);
    g.bond(one, i2, Domain::Mechanical);
    let d = causality::assign(&mut g).unwrap();
    assert_eq!(d.len(), 1);
    assert_eq!((d[0].node, d[0].state), (i2, Store::Momentum(1)));
    assert!(
        d[0].meaning.contains("velocity is imposed"),
        "{}",
        d[0].meaning
    );
    common::bond::one_stroke_per_bond(&g, "rigid");
    common::bond::junctions_consistent(&g, "rigid");
}

/// Two effort sources on one 0-junction contradict each other.
#[test]
fn two_efforts_on_a_zero_junction_conflict() {
    let mut g = BondGraph::new("clash");
    let zero = g.node(Kind::Zero, "P");
    let a = g.node(Kind::Se, "P1");
    let b = g.node(Kind::Se, "P2");
    g.bond(a, zero, Domain::Volume);
    g.bond(b, zero, Domain::Volume);
    let e = causality::assign(&mut g).unwrap_err();
    assert!(
        matches!(e, BondError::Conflict(ref at) if at.contains("Se: P2")),
        "{e}"
    );
}

/// The DOT of `cv1`, reviewed: strokes, half-arrows, junctions and labels.
#[test]
fn cv1_bond_graph_dot() {
    let m = build("cv1", None, Closure::Full).unwrap();
    insta::assert_snapshot!("cv1_bond_graph", check(m.as_ref()).to_dot());
}

/// The SVG drawing (no Graphviz): one stroke and one half-arrow per bond, every label as
/// text, and no two boxes overlapping, for `cv1` and `nsection` at 1, 2 and 10 sections (set
/// `BOND_SVG_DIR` to write them there and look at them).
#[test]
fn svg_draws_every_bond_and_label_without_overlaps() {
    let models = [
        build("cv1", None, Closure::Full).unwrap(),
        build("nsection", Some(1), Closure::Full).unwrap(),
        build("nsection", Some(2), Closure::Full).unwrap(),
        build("nsection", Some(10), Closure::Full).unwrap(),
    ];
    for m in &models {
        let cg = check(m.as_ref());
        let svg = cg.to_svg();
        // to look at the pictures: BOND_SVG_DIR=/tmp/svg cargo test --test bond_graph svg
        if let Some(dir) = std::env::var_os("BOND_SVG_DIR") {
            let file = std::path::Path::new(&dir).join(format!("{}_{}.svg", m.name(), m.n()));
            std::fs::write(file, &svg).unwrap();
        }
        let bonds = cg.graph.bonds.len();
        assert_eq!(svg.matches("class=\"stroke\"").count(), bonds);
        assert_eq!(svg.matches("class=\"half-arrow\"").count(), bonds);
        for n in &cg.graph.nodes {
            let text = n
                .text()
                .replace('&', "&amp;")
                .replace('<', "&lt;")
                .replace('>', "&gt;");
            assert!(
                svg.contains(&format!(">{text}</text>")),
                "{}: no `{text}`",
                m.name()
            );
        }
        let lay = stirling::dsl::bond::layout::layered(&cg.graph);
        for a in 0..lay.centre.len() {
            for b in a + 1..lay.centre.len() {
                let (ca, cb, ha, hb) = (lay.centre[a], lay.centre[b], lay.half[a], lay.half[b]);
                let apart =
                    (ca.0 - cb.0).abs() >= ha.0 + hb.0 || (ca.1 - cb.1).abs() >= ha.1 + hb.1;
                assert!(apart, "{} n={}: nodes {a} and {b} overlap", m.name(), m.n());
            }
        }
    }
}

/// The SVG of `cv1`, reviewed (structure and coordinates).
#[test]
fn cv1_bond_graph_svg() {
    let m = build("cv1", None, Closure::Full).unwrap();
    insta::assert_snapshot!("cv1_bond_graph_svg", check(m.as_ref()).to_svg());
}
