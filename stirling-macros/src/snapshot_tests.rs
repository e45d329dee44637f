//! Snapshots of the pure expansion (formatted with prettyplease) and of the printed
//! equations, for small models: review them like code.

use proc_macro2::{TokenStream, TokenTree};

use crate::expand::expand;
use stirling_front::ast::ModelAst;

/// One gas space on one piston with one heat port, against a bounce space.
const ONE_CV: &str = r#"
    /// One gas space on one piston.
    pub model OneCv {
        params {
            /// specific gas constant
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.3 "kg",
            k: 60.0 "N/m",
            A: 2.6e-3 "m^2",
            V0: 1.5e-4 "m^3",
            Tw: 450.0 "K",
            h: 500.0 "W/(m^2 K)",
            Aw: 0.0128 "m^2",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space bounce { pressure: P0, faces { piston: A } }
        cv gas { volume: V0, faces { piston: -A }, port wall { h: h, area: Aw, wall: Tw } }
    }
"#;

/// Two CVs joined by one link, on one piston.
const TWO_CV: &str = r#"
    /// Two gas spaces joined by a flow resistance.
    pub model TwoCv {
        params {
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.3 "kg",
            k: 60.0 "N/m",
            A: 2.6e-3 "m^2",
            V1: 1.5e-4 "m^3",
            V2: 1.2e-4 "m^3",
            Th: 600.0 "K",
            Tk: 300.0 "K",
            h: 500.0 "W/(m^2 K)",
            Aw: 0.0128 "m^2",
            Rf: 1.0e5 "Pa s/kg",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space bounce { pressure: P0, faces { piston: A } }
        cv hot { volume: V1, port heater { h: h, area: Aw, wall: Th } }
        cv cold { volume: V2, faces { piston: -A }, port cooler { h: h, area: Aw, wall: Tk } }
        link hot -> cold { resistance: Rf }
    }
"#;

/// A regenerator chain `r[n]` whose matrix `matrix[n]` is a thermal mass, conducting along
/// itself and to the fixed ends.
const WALL_ARRAY: &str = r#"
    /// A hot CV and a regenerator chain with a matrix of finite heat capacity.
    pub model WallArray {
        params {
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.3 "kg",
            k: 60.0 "N/m",
            A: 2.6e-3 "m^2",
            V0: 1.5e-4 "m^3",
            Vr: 4.0e-5 "m^3",
            Th: 600.0 "K",
            Tk: 300.0 "K",
            h: 100.0 "W/(m^2 K)",
            Aw: 0.0377 "m^2",
            Rf: 1.0e5 "Pa s/kg",
            Cm: 25.0 "J/K",
            Gm: 0.03 "W/K",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        space bounce { pressure: P0, faces { piston: A } }
        cv hot { volume: V0, faces { piston: -A }, port heater { h: h, area: Aw, wall: Th } }
        cv r[n] { volume: Vr / n, port matrix { h: h, area: Aw / n, wall: matrix[j] } }
        wall matrix[n] { capacity: Cm / n, rest: Th - (j + 0.5) * (Th - Tk) / n }
        link hot -> r[0] { resistance: Rf / n }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
    }
"#;

/// A regenerator chain `r[n]` whose every section leaks into one closed bounce CV: the
/// bounce's rows hold the sum over the sections (`S0`, `S1`).
const PER_SECTION: &str = r#"
    /// A hot CV and a regenerator chain leaking section by section into a closed bounce.
    pub model PerSection {
        params {
            R: 287.05 "J/(kg K)",
            gamma: 1.4 "-",
            P0: 101325.0 "Pa",
            m: 0.3 "kg",
            k: 60.0 "N/m",
            A: 2.6e-3 "m^2",
            V0: 1.5e-4 "m^3",
            Vr: 4.0e-5 "m^3",
            Vb: 2.0e-3 "m^3",
            Th: 600.0 "K",
            Tk: 300.0 "K",
            h: 100.0 "W/(m^2 K)",
            Aw: 0.0377 "m^2",
            Rf: 1.0e5 "Pa s/kg",
            Rl: 1.0e8 "Pa s/kg",
            eps: 1.0e-5 "kg/s",
        }
        gas { R: R, gamma: gamma, charge: P0, mdot_eps: eps }
        body piston(y, w) { mass: m, spring: k }
        cv bounce { volume: Vb, faces { piston: A }, port wall { h: h, area: Aw, wall: Tk } }
        cv hot { volume: V0, faces { piston: -A }, port heater { h: h, area: Aw, wall: Th } }
        cv r[n] { volume: Vr / n, port wall { h: h, area: Aw / n, wall: Tk } }
        link hot -> r[0] { resistance: Rf / n }
        link r[j] -> r[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link r[j] -> bounce for j in 0..n { resistance: Rl * n }
    }
"#;

fn parse(src: &str) -> ModelAst {
    syn::parse_str(src).expect("the test model parses")
}

/// The expansion, formatted.
fn expanded(src: &str) -> String {
    let tokens = expand(parse(src)).unwrap_or_else(|e| panic!("expansion failed: {e}"));
    let file: syn::File = syn::parse2(tokens).expect("the expansion is valid Rust");
    prettyplease::unparse(&file)
}

/// Only the generated methods named `names` of the expansion, formatted.
fn methods(src: &str, names: &[&str]) -> String {
    let tokens = expand(parse(src)).unwrap_or_else(|e| panic!("expansion failed: {e}"));
    let mut file: syn::File = syn::parse2(tokens).expect("the expansion is valid Rust");
    file.items.retain_mut(|item| match item {
        syn::Item::Impl(imp) if imp.trait_.is_none() => {
            imp.items.retain(|it| matches!(it, syn::ImplItem::Fn(f) if names.contains(&f.sig.ident.to_string().as_str())));
            !imp.items.is_empty()
        }
        _ => false,
    });
    prettyplease::unparse(&file)
}

/// The printed text equations of one closure, as the expansion embeds them
/// (the string literal of `Model::equations` that starts with `header`).
fn equations(src: &str, header: &str) -> String {
    fn find(ts: TokenStream, header: &str, out: &mut Vec<String>) {
        for tt in ts {
            match tt {
                TokenTree::Group(g) => find(g.stream(), header, out),
                TokenTree::Literal(l) => {
                    if let Ok(s) = syn::parse_str::<syn::LitStr>(&l.to_string()) {
                        if s.value().starts_with(header) {
                            out.push(s.value());
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let mut found = Vec::new();
    find(expand(parse(src)).expect("expansion"), header, &mut found);
    assert_eq!(found.len(), 1, "one equations text starts with {header:?}");
    found.remove(0)
}

#[test]
fn expansion_one_cv() {
    insta::assert_snapshot!(expanded(ONE_CV));
}

#[test]
fn expansion_two_cv() {
    insta::assert_snapshot!(expanded(TWO_CV));
}

#[test]
fn equations_two_cv_full() {
    insta::assert_snapshot!(equations(TWO_CV, "model twocv, closure full"));
}

#[test]
fn equations_two_cv_frozen() {
    insta::assert_snapshot!(equations(TWO_CV, "model twocv, closure frozen"));
}

/// The generated Rust of a wall array: the right-hand side, the Jacobian and the walls'
/// energy terms of the full closure.
#[test]
fn expansion_wall_array() {
    insta::assert_snapshot!(methods(
        WALL_ARRAY,
        &["__rhs_full", "__jac_full", "__walls_full"]
    ));
}

#[test]
fn equations_wall_array_full() {
    insta::assert_snapshot!(equations(WALL_ARRAY, "model wallarray, closure full"));
}

/// The generated Rust of a per-section link: the sums' prologue loop, and the chain-rule
/// loops of the bounce's rows (the arrow) in the Jacobians.
#[test]
fn expansion_per_section() {
    insta::assert_snapshot!(methods(
        PER_SECTION,
        &["__rhs_full", "__jac_full", "__pjac_full"]
    ));
}

#[test]
fn equations_per_section_full() {
    insta::assert_snapshot!(equations(PER_SECTION, "model persection, closure full"));
}

/// The generated Rust of `nsection` itself (the family's engine as one model): the right-hand
/// side and the Jacobian whose operations per section docs/performance.md counts.
#[test]
fn expansion_nsection() {
    insta::assert_snapshot!(methods(
        crate::flop_count::NSECTION,
        &["__rhs_full", "__jac_full"]
    ));
}
