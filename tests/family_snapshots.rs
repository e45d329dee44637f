//! Snapshots a person reviews: the printed equations of `cv1` and of `nsection` at n = 2
//! (text), and the bond graph (DOT) of `cv2`. Review changes with `cargo insta review`.

use stirling::dsl::bond::bond_graph;
use stirling::dsl::{Closure, Style};
use stirling::models::build;

#[test]
fn cv1_equations_text() {
    let m = build("cv1", None, Closure::Full).unwrap();
    insta::assert_snapshot!("cv1_equations", m.equations(Style::Text));
}

#[test]
fn nsection_2_equations_text() {
    let m = build("nsection", Some(2), Closure::Full).unwrap();
    insta::assert_snapshot!("nsection_2_equations", m.equations(Style::Text));
}

#[test]
fn cv2_bond_graph_dot() {
    let m = build("cv2", None, Closure::Full).unwrap();
    insta::assert_snapshot!("cv2_dot", bond_graph(m.as_ref()).unwrap().to_dot());
}

/// The equations of `cv1` do not depend on the closure: it has no links, so its mass is a constant.
#[test]
fn cv1_equations_are_the_same_for_both_closures() {
    let full = build("cv1", None, Closure::Full)
        .unwrap()
        .equations(Style::Text);
    let frozen = build("cv1", None, Closure::Frozen)
        .unwrap()
        .equations(Style::Text);
    let body = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
    assert_eq!(body(&full), body(&frozen));
}
