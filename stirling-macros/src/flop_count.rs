//! Floating-point operations per regenerator section of the generated `nsection` code
//! (docs/performance.md, "Operations per section"): the body of the loop over the
//! interior sections of `__rhs_full`, `__jac_full` and `__rhs_jac_full`, counted on the
//! expansion, held to the documented counts as ceilings. Run: `cargo test -p
//! stirling-macros flop_count -- --nocapture`.
//!
//! Counted: binary `+ - * /` on `f64` values (index arithmetic inside `[..]` and the row
//! and column arguments of `sink.add` are integer work and not counted), and calls of
//! `tanh`, `powi`, `sqrt`, `exp`, `powf`, `ln`. A unary minus is a sign flip and not counted;
//! stores (`out[..] =`, Jacobian entries) are listed apart.

use proc_macro2::{Delimiter, TokenStream, TokenTree};

use crate::expand::expand;
use stirling_front::ast::ModelAst;

/// `nsection` as one model (the engine base and the `nsection` gas of stirling-models).
pub(crate) const NSECTION: &str = r#"
    pub model NSectionFlat {
        params {
            R: 287.05 "J/(kg K)", gamma: 1.4 "-", A: 0.0028274 "m^2", Ar: 0.00017671 "m^2",
            Vh0: 1.5e-4 "m^3", Vc0: 1.2e-4 "m^3", Vr: 4.0e-5 "m^3", Th: 600.0 "K", Tk: 300.0 "K",
            Pmean: 101325.0 "Pa", Pb: 101325.0 "Pa", md: 0.08228 "kg", mp: 0.33363 "kg",
            kd: 650.74 "N/m", kp: 61.482 "N/m", bd: 0.48643 "N s/m", bp: 7.9083 "N s/m",
            b: 0.1 "N s/m", bqd: 0.5 "N s^2/m^2", bqp: 5.0 "N s^2/m^2", Awh0: 0.0128 "m^2",
            Awc0: 0.0112 "m^2", Awr: 0.0377 "m^2", hh: 500.0 "W/(m^2 K)", hk: 500.0 "W/(m^2 K)",
            hr: 100.0 "W/(m^2 K)", Rf: 1.0e5 "Pa s/kg", mdot_eps: 1.0e-5 "kg/s",
        }
        let D = sqrt(4.0 * A / pi);
        gas { R: R, gamma: gamma, charge: Pmean, mdot_eps: mdot_eps }
        body displacer(x, v) { mass: md, spring: kd, damper: bd, quad_damper: bqd }
        body piston(y, w) { mass: mp, spring: kp, damper: bp, quad_damper: bqp }
        coupling displacer, piston { damper: b }
        space bounce { pressure: Pb, faces { displacer: Ar, piston: A - Ar } }
        cv hot {
            volume: Vh0,
            faces { displacer: -A },
            port hot { h: hh, area: Awh0 - pi * D * x, wall: Th },
        }
        cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Th - (j + 0.5) * (Th - Tk) / n },
        }
        cv cold {
            volume: Vc0,
            faces { displacer: A - Ar, piston: -(A - Ar) },
            port cold { h: hk, area: Awc0 + pi * D * (x - y), wall: Tk },
        }
        link hot -> regen[0] { resistance: Rf / (2.0 * n) }
        link regen[j] -> regen[j + 1] for j in 0..n - 1 { resistance: Rf / n }
        link regen[n - 1] -> cold { resistance: Rf / (2.0 * n) }
    }
"#;

/// Operation counts of one piece of code.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Counts {
    pub add_sub: usize,
    pub mul: usize,
    pub div: usize,
    pub calls: Vec<String>,
    pub stores: usize,
}

impl Counts {
    fn flops(&self) -> usize {
        self.add_sub + self.mul + self.div
    }
}

/// The token stream of the body of `fn name` in `ts`, if any.
fn function(ts: TokenStream, name: &str) -> Option<TokenStream> {
    let toks: Vec<TokenTree> = ts.into_iter().collect();
    for (i, t) in toks.iter().enumerate() {
        if let TokenTree::Group(g) = t {
            if let Some(f) = function(g.stream(), name) {
                return Some(f);
            }
        }
        if matches!(t, TokenTree::Ident(id) if id == "fn")
            && matches!(toks.get(i + 1), Some(TokenTree::Ident(id)) if id == name)
        {
            return toks[i + 2..].iter().find_map(|t| match t {
                TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some(g.stream()),
                _ => None,
            });
        }
    }
    None
}

/// The body of the loop `for j in 1..` (the interior sections) in `ts`, or of the arm
/// `Variant::Interior => { .. }` (the code before the sections were peeled).
fn interior_loop(ts: TokenStream) -> Option<TokenStream> {
    let toks: Vec<TokenTree> = ts.into_iter().collect();
    for (i, t) in toks.iter().enumerate() {
        let is_for = matches!(t, TokenTree::Ident(id) if id == "for");
        let from_one =
            matches!(toks.get(i + 3), Some(TokenTree::Literal(l)) if l.to_string() == "1");
        let arm = matches!(t, TokenTree::Ident(id) if id == "Interior");
        if (is_for && from_one) || arm {
            return toks[i..].iter().find_map(|t| match t {
                TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some(g.stream()),
                _ => None,
            });
        }
        if let TokenTree::Group(g) = t {
            if let Some(b) = interior_loop(g.stream()) {
                return Some(b);
            }
        }
    }
    None
}

/// Count the operations of `ts` (see the module docs).
fn count(ts: TokenStream, c: &mut Counts) {
    let toks: Vec<TokenTree> = ts.into_iter().collect();
    let mut prev_operand = false;
    for (i, t) in toks.iter().enumerate() {
        match t {
            TokenTree::Punct(p) => {
                match p.as_char() {
                    '+' | '-' if prev_operand => c.add_sub += 1,
                    '*' if prev_operand => c.mul += 1,
                    '/' if prev_operand => c.div += 1,
                    _ => {}
                }
                prev_operand = false;
            }
            TokenTree::Ident(id) => {
                let name = id.to_string();
                let after_dot = matches!(toks.get(i.wrapping_sub(1)), Some(TokenTree::Punct(p)) if p.as_char() == '.');
                // `::stirling_dsl::__private::tanh(..)`: the inlined `tanh` (expr/tanh.rs)
                let after_path = matches!(toks.get(i.wrapping_sub(1)), Some(TokenTree::Punct(p)) if p.as_char() == ':');
                if (after_dot
                    && ["tanh", "powi", "sqrt", "exp", "powf", "ln"].contains(&name.as_str()))
                    || (after_path && name == "tanh")
                {
                    c.calls.push(name.clone());
                }
                prev_operand = !["let", "mut", "return"].contains(&name.as_str());
            }
            TokenTree::Literal(_) => prev_operand = true,
            TokenTree::Group(g) => {
                match g.delimiter() {
                    // an index: integer arithmetic; a store when `=` follows
                    Delimiter::Bracket => {
                        let store = matches!(toks.get(i + 1), Some(TokenTree::Punct(p)) if p.as_char() == '=');
                        c.stores += store as usize;
                    }
                    Delimiter::Parenthesis if is_call(&toks, i, "add") => {
                        c.stores += 1;
                        count_values(g.stream(), 2, c)
                    }
                    Delimiter::Parenthesis if is_call(&toks, i, "add_all") => {
                        count_entries(g.stream(), c)
                    }
                    _ => count(g.stream(), c),
                }
                prev_operand = true;
            }
        }
    }
}

fn is_call(toks: &[TokenTree], i: usize, name: &str) -> bool {
    i >= 2 && matches!(&toks[i - 1], TokenTree::Ident(id) if id == name)
}

/// The entries `&[(row, col, value), ..]` of `sink.add_all`: one store each.
fn count_entries(ts: TokenStream, c: &mut Counts) {
    for t in ts {
        if let TokenTree::Group(list) = t {
            for e in list.stream() {
                if let TokenTree::Group(entry) = e {
                    c.stores += 1;
                    count_values(entry.stream(), 2, c);
                }
            }
        }
    }
}

/// Count the arguments of a call after the first `skip` ones.
fn count_values(ts: TokenStream, skip: usize, c: &mut Counts) {
    let mut commas = 0;
    let mut rest = TokenStream::new();
    for t in ts {
        if commas >= skip {
            rest.extend([t]);
        } else if matches!(&t, TokenTree::Punct(p) if p.as_char() == ',') {
            commas += 1;
        }
    }
    count(rest, c);
}

fn counts_of(expansion: &TokenStream, method: &str) -> Option<Counts> {
    let body = interior_loop(function(expansion.clone(), method)?)?;
    let mut c = Counts::default();
    count(body, &mut c);
    Some(c)
}

#[test]
fn flop_count() {
    let ast: ModelAst = syn::parse_str(NSECTION).expect("nsection parses");
    let expansion = expand(ast).expect("nsection expands");
    if std::env::var_os("FLOP_DUMP").is_some() {
        let file: syn::File = syn::parse2(expansion.clone()).expect("valid Rust");
        println!("{}", prettyplease::unparse(&file));
    }
    println!("| function | add/sub | mul | div | flops | calls | stores |");
    println!("|---|---|---|---|---|---|---|");
    // the counts of docs/performance.md, as ceilings: a change of the generator that makes the
    // section loop do more (a division back, a second `tanh` per link) fails here
    let ceilings = [
        ("__rhs_full", 25, 1, 2),
        ("__jac_full", 53, 1, 9),
        ("__rhs_jac_full", 65, 1, 11),
    ];
    for (m, flops, divs, stores) in ceilings {
        let c = counts_of(&expansion, m).expect("nsection has an interior loop");
        assert!(
            c.flops() <= flops,
            "{m}: {} flops per section > {flops}",
            c.flops()
        );
        assert!(
            c.div <= divs,
            "{m}: {} divisions per section > {divs}",
            c.div
        );
        assert_eq!(c.stores, stores, "{m}: stores per section");
        let tanh = c.calls.iter().filter(|f| *f == "tanh").count();
        assert_eq!(tanh, 1, "{m}: one tanh per section (the link's, carried)");
    }
    for m in ["__rhs_full", "__jac_full", "__rhs_jac_full"] {
        let Some(c) = counts_of(&expansion, m) else {
            println!("| {m} | (no interior loop) |");
            continue;
        };
        println!(
            "| {m} | {} | {} | {} | {} | {} | {} |",
            c.add_sub,
            c.mul,
            c.div,
            c.flops(),
            c.calls.join(", "),
            c.stores
        );
    }
}
