//! Unit tests of the expression core: folding constructors, differentiation against
//! finite differences, one-line printing and Rust emission.

use proc_macro2::TokenStream;
use quote::quote;

use super::emit::emit_block;
use super::{Arena, At, Func, Id, Printer, Style, Sym};

const X: Sym = Sym::State(0, At::Scalar);
const Y: Sym = Sym::State(1, At::Scalar);

fn namer(s: Sym) -> String {
    match s {
        X => "x".into(),
        Y => "y".into(),
        Sym::Param(i) => format!("p{i}"),
        other => format!("{other:?}"),
    }
}

fn text(a: &Arena, id: Id) -> String {
    Printer::new(a, Style::Text, &namer).expr(id)
}

fn xy(a: &mut Arena) -> (Id, Id) {
    (a.sym(X), a.sym(Y))
}

fn eval_at(a: &Arena, id: Id, x: f64, y: f64) -> f64 {
    a.eval(id, &mut |s| match s {
        X => x,
        Y => y,
        _ => f64::NAN,
    })
}

// ---- folding -------------------------------------------------------------------------

#[test]
fn folds_zero_and_one() {
    let mut a = Arena::new();
    let (x, _) = xy(&mut a);
    let (zero, one) = (a.num(0.0), a.num(1.0));
    assert_eq!(a.add(x, zero), x);
    assert_eq!(a.add(zero, x), x);
    assert_eq!(a.sub(x, zero), x);
    assert_eq!(a.mul(x, one), x);
    assert_eq!(a.mul(one, x), x);
    assert_eq!(a.mul(x, zero), zero);
    assert_eq!(a.mul(zero, x), zero);
    assert_eq!(a.div(x, one), x);
    assert_eq!(a.div(zero, x), zero);
    assert_eq!(a.sub(x, x), zero);
    assert_eq!(a.div(x, x), one);
    assert_eq!(a.powi(x, 1), x);
    assert_eq!(a.powi(x, 0), one);
    let negzero = a.num(-0.0);
    assert_eq!(negzero, zero, "one representation of zero");
}

#[test]
fn folds_constants() {
    let mut a = Arena::new();
    let (two, three) = (a.num(2.0), a.num(3.0));
    let cases = [
        (a.add(two, three), 5.0),
        (a.sub(two, three), -1.0),
        (a.mul(two, three), 6.0),
        (a.div(three, two), 1.5),
        (a.powi(two, 3), 8.0),
        (a.func(Func::Sqrt, two), 2f64.sqrt()),
    ];
    for (id, v) in cases {
        assert_eq!(a.as_const(id), Some(v));
    }
    let zero = a.num(0.0);
    let inf = a.div(two, zero);
    assert_eq!(a.as_const(inf), None, "never folds a division by zero");
}

#[test]
fn folds_negation() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let nx = a.neg(x);
    assert_eq!(a.neg(nx), x, "--x = x");
    let minus_one = a.num(-1.0);
    assert_eq!(a.mul(minus_one, x), nx);
    assert_eq!(a.div(x, minus_one), nx);
    let ny = a.neg(y);
    let (sum, diff) = (a.add(x, ny), a.sub(x, y));
    assert_eq!(sum, diff, "x + -y = x - y");
    let s = a.sub(x, ny);
    assert_eq!(text(&a, s), "x + y");
    let d = a.sub(x, y);
    let nd = a.neg(d);
    assert_eq!(text(&a, nd), "y - x", "-(x - y) = y - x");
    let p = a.mul(nx, ny);
    assert_eq!(text(&a, p), "x * y", "(-x)(-y) = x y");
    let two = a.num(2.0);
    let neg2 = a.neg(two);
    assert_eq!(a.as_const(neg2), Some(-2.0));
}

#[test]
fn shares_equal_nodes() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let s1 = a.add(x, y);
    let s2 = a.add(x, y);
    assert_eq!(s1, s2);
    let two = a.num(2.0);
    let (l, r) = (a.mul(x, two), a.mul(two, x));
    assert_eq!(l, r, "constants to the left");
}

// ---- differentiation -----------------------------------------------------------------

/// `d/dx` of `build(x, y)` against a central difference at several points.
fn check_diff(name: &str, build: impl Fn(&mut Arena, Id, Id) -> Id, points: &[(f64, f64)]) {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let e = build(&mut a, x, y);
    let (dx, dy) = (a.diff(e, X), a.diff(e, Y));
    for &(px, py) in points {
        for (d, h, which) in [(dx, (1e-4, 0.0), "x"), (dy, (0.0, 1e-4), "y")] {
            let analytic = eval_at(&a, d, px, py);
            let fd = |s: f64| {
                let (hx, hy) = (h.0 * s, h.1 * s);
                (eval_at(&a, e, px + hx, py + hy) - eval_at(&a, e, px - hx, py - hy))
                    / (2.0 * s * 1e-4)
            };
            // one Richardson step: error O(h^4)
            let numeric = (4.0 * fd(0.5) - fd(1.0)) / 3.0;
            let err = (analytic - numeric).abs() / analytic.abs().max(1.0);
            assert!(
                err < 1e-9,
                "d/d{which} {name} at ({px}, {py}): analytic {analytic}, fd {numeric}"
            );
        }
    }
}

const POINTS: &[(f64, f64)] = &[(0.7, 1.3), (1.9, 0.4), (-0.6, 2.2)];
const POSITIVE: &[(f64, f64)] = &[(0.7, 1.3), (1.9, 0.4), (3.1, 2.2)];

#[test]
fn diff_of_arithmetic() {
    check_diff("x + y", |a, x, y| a.add(x, y), POINTS);
    check_diff("x - y", |a, x, y| a.sub(x, y), POINTS);
    check_diff(
        "-x y",
        |a, x, y| {
            let m = a.mul(x, y);
            a.neg(m)
        },
        POINTS,
    );
    check_diff("x * y", |a, x, y| a.mul(x, y), POINTS);
    check_diff("x / y", |a, x, y| a.div(x, y), POINTS);
    check_diff(
        "x^3 y^-2",
        |a, x, y| {
            let (p, q) = (a.powi(x, 3), a.powi(y, -2));
            a.mul(p, q)
        },
        POINTS,
    );
    check_diff("x^y", |a, x, y| a.powf(x, y), POSITIVE);
}

#[test]
fn diff_of_functions() {
    for f in [
        Func::Sqrt,
        Func::Ln,
        Func::Exp,
        Func::Tanh,
        Func::Abs,
        Func::Sin,
        Func::Cos,
    ] {
        let pts = if matches!(f, Func::Sqrt | Func::Ln) {
            POSITIVE
        } else {
            POINTS
        };
        check_diff(
            f.name(),
            |a, x, y| {
                let xy = a.mul(x, y);
                a.func(f, xy)
            },
            pts,
        );
    }
    // sign is piecewise constant: derivative 0 away from 0
    let mut a = Arena::new();
    let (x, _) = xy(&mut a);
    let s = a.func(Func::Sign, x);
    let ds = a.diff(s, X);
    assert_eq!(a.as_const(ds), Some(0.0));
}

#[test]
fn diff_of_the_upwind_enthalpy() {
    // H = mdot (y + (1 + tanh(mdot / 0.01)) / 2 (1 - y)), the link law of docs/physics.md 4
    check_diff(
        "enthalpy",
        |a, x, y| {
            let (one, half, eps) = (a.num(1.0), a.num(0.5), a.num(0.01));
            let r = a.div(x, eps);
            let t = a.func(Func::Tanh, r);
            let o = a.add(one, t);
            let s = a.mul(half, o);
            let d = a.sub(one, y);
            let sd = a.mul(s, d);
            let up = a.add(y, sd);
            a.mul(x, up)
        },
        &[(0.003, 1.3), (-0.004, 0.4), (0.0, 2.0)],
    );
}

#[test]
fn diff_is_exact_for_polynomials() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let three = a.num(3.0);
    let x2 = a.powi(x, 2);
    let t = a.mul(three, x2);
    let e = a.add(t, y);
    let d = a.diff(e, X);
    assert_eq!(text(&a, d), "3 * (2 * x)");
    let dy = a.diff(e, Y);
    assert_eq!(a.as_const(dy), Some(1.0));
    let dz = a.diff(e, Sym::Param(0));
    assert_eq!(a.as_const(dz), Some(0.0), "no dependence folds to zero");
}

#[test]
fn diff_sees_through_names() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let xy = a.mul(x, y);
    let named = a.named("q", xy);
    let e = a.func(Func::Sin, named);
    assert_eq!(text(&a, e), "sin(q)");
    let d = a.diff(e, X);
    assert_eq!(text(&a, d), "cos(q) * y");
}

// ---- printing ------------------------------------------------------------------------

#[test]
fn prints_one_line() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let two = a.num(2.0);
    let tx = a.mul(two, x);
    let sy = a.func(Func::Sin, y);
    let e = a.add(tx, sy);
    assert_eq!(text(&a, e), "2 * x + sin(y)");
    let s = a.sub(x, y);
    let q = a.div(s, tx);
    assert_eq!(text(&a, q), "(x - y) / (2 * x)");
    let sxy = a.add(x, y);
    let d = a.sub(x, sxy);
    assert_eq!(text(&a, d), "x - (x + y)");
    let p = a.powi(s, -2);
    assert_eq!(text(&a, p), "(x - y)^(-2)");
    let n = a.neg(sxy);
    assert_eq!(text(&a, n), "-(x + y)");
    let g = a.sym(Sym::Param(0));
    let big = a.num(1.0e-5);
    let m = a.mul(big, g);
    assert_eq!(text(&a, m), "1e-5 * p0");
    let sg = a.func(Func::Sign, x);
    assert_eq!(text(&a, sg), "sign(x)");
}

#[test]
fn prints_latex() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let q = a.div(x, y);
    let r = a.func(Func::Sqrt, q);
    assert_eq!(
        Printer::new(&a, Style::Latex, &namer).expr(r),
        "\\sqrt{\\frac{x}{y}}"
    );
}

#[test]
fn prints_definitions_inner_first() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let s = a.add(x, y);
    let v = a.named("V", s);
    let two = a.num(2.0);
    let t = a.mul(two, v);
    let w = a.named("W", t);
    let e = a.mul(w, v);
    let p = Printer::new(&a, Style::Text, &namer);
    assert_eq!(p.expr(e), "W * V");
    assert_eq!(
        p.definitions(&[e]),
        vec![
            ("V".to_string(), "x + y".to_string()),
            ("W".to_string(), "2 * V".to_string())
        ]
    );
}

// ---- emission ------------------------------------------------------------------------

fn leaf(s: Sym) -> TokenStream {
    match s {
        X => quote!(x[0]),
        Y => quote!(x[1]),
        _ => quote!(unknown),
    }
}

fn compact(t: &TokenStream) -> String {
    t.to_string()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn emits_an_expression_with_shared_temporaries() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let s = a.add(x, y);
    let sn = a.func(Func::Sin, s);
    let two = a.num(2.0);
    let p = a.mul(two, s);
    let out = a.div(sn, p);
    let sg = a.func(Func::Sign, x);
    let block = emit_block(&a, &[out, sg], &leaf, &quote!(crate::__private));
    let lets: Vec<String> = block.lets.iter().map(compact).collect();
    assert_eq!(lets, vec!["let t0 = x [0] + x [1] ;"]);
    assert_eq!(compact(&block.outputs[0]), "t0 . sin () / (2.0 * t0)");
    assert_eq!(
        compact(&block.outputs[1]),
        "crate :: __private :: sign (x [0])"
    );
}

#[test]
fn emits_named_quantities_by_name() {
    let mut a = Arena::new();
    let (x, y) = xy(&mut a);
    let m = a.mul(x, y);
    let v = a.named("V_hot", m);
    let neg = a.neg(v);
    let block = emit_block(&a, &[neg], &leaf, &quote!(p));
    let lets: Vec<String> = block.lets.iter().map(compact).collect();
    assert_eq!(lets, vec!["let V_hot = x [0] * x [1] ;"]);
    assert_eq!(compact(&block.outputs[0]), "- V_hot");
}

#[test]
fn emitted_numbers_read_back() {
    let mut a = Arena::new();
    let (x, _) = xy(&mut a);
    for v in [0.1, 1.0e-5, 287.05, -3.5] {
        let c = a.num(v);
        let e = a.mul(c, x);
        let block = emit_block(&a, &[e], &leaf, &quote!(p));
        let text = compact(&block.outputs[0]);
        let lit = text.split(" * ").next().unwrap().replace(' ', "");
        assert_eq!(lit.parse::<f64>().unwrap(), v, "{text}");
    }
}
