//! DSL expressions (Rust syntax) into the symbolic arena.
//!
//! Accepted: numbers, `+ - * /`, unary `-`, parentheses, `pi`, parameters, `let`
//! names, body states, `n` (sections) and the section index inside arrays; the
//! functions `sqrt ln exp tanh abs sign sin cos` as calls or methods, and
//! `powi(x, k)` / `x.powi(k)`, `powf(x, y)` / `x.powf(y)`.

use std::collections::HashMap;

use stirling_dsl::expr::{Arena, Func, Id, Sym};
use syn::spanned::Spanned;
use syn::{BinOp, Expr, Lit, UnOp};

/// The names an expression may use.
pub struct Scope<'a> {
    pub params: &'a HashMap<String, u32>,
    pub lets: &'a HashMap<String, Id>,
    pub states: &'a HashMap<String, Sym>,
    /// The name of the section index, where one is in scope.
    pub index: Option<String>,
}

fn err<T>(e: &impl Spanned, msg: impl std::fmt::Display) -> syn::Result<T> {
    Err(syn::Error::new(e.span(), msg))
}

/// Convert `e`.
pub fn convert(a: &mut Arena, scope: &Scope, e: &Expr) -> syn::Result<Id> {
    match e {
        Expr::Lit(l) => literal(a, &l.lit),
        Expr::Paren(p) => convert(a, scope, &p.expr),
        Expr::Group(g) => convert(a, scope, &g.expr),
        Expr::Path(p) => match p.path.get_ident() {
            Some(id) => name(a, scope, id),
            None => err(p, "expected a single name, not a path"),
        },
        Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => {
            let x = convert(a, scope, &u.expr)?;
            Ok(a.neg(x))
        }
        Expr::Binary(b) => binary(a, scope, b),
        Expr::Call(c) => call(a, scope, c),
        Expr::MethodCall(m) => method(a, scope, m),
        other => err(other, "unsupported expression: expected numbers, names, + - * /, or sqrt/ln/exp/tanh/abs/sign/sin/cos/powi/powf"),
    }
}

fn literal(a: &mut Arena, l: &Lit) -> syn::Result<Id> {
    match l {
        Lit::Float(f) => Ok(a.num(f.base10_parse::<f64>()?)),
        Lit::Int(i) => Ok(a.num(i.base10_parse::<f64>()?)),
        other => err(other, "expected a number"),
    }
}

fn name(a: &mut Arena, scope: &Scope, id: &syn::Ident) -> syn::Result<Id> {
    let s = id.to_string();
    if let Some(&v) = scope.lets.get(&s) {
        return Ok(v);
    }
    if let Some(&k) = scope.params.get(&s) {
        return Ok(a.sym(Sym::Param(k)));
    }
    if let Some(&st) = scope.states.get(&s) {
        return Ok(a.sym(st));
    }
    if scope.index.as_deref() == Some(s.as_str()) {
        return Ok(a.sym(Sym::Index));
    }
    match s.as_str() {
        "n" => Ok(a.sym(Sym::Count)),
        "pi" => Ok(a.num(std::f64::consts::PI)),
        _ => {
            let index = scope
                .index
                .as_ref()
                .map(|i| format!(", the section index `{i}`"))
                .unwrap_or_default();
            err(id, format!("unknown name `{s}`: expected a parameter, a `let` name, a body state, `n`{index} or `pi`"))
        }
    }
}

fn binary(a: &mut Arena, scope: &Scope, b: &syn::ExprBinary) -> syn::Result<Id> {
    let (x, y) = (convert(a, scope, &b.left)?, convert(a, scope, &b.right)?);
    Ok(match b.op {
        BinOp::Add(_) => a.add(x, y),
        BinOp::Sub(_) => a.sub(x, y),
        BinOp::Mul(_) => a.mul(x, y),
        BinOp::Div(_) => a.div(x, y),
        _ => {
            return err(
                &b.op,
                "unsupported operator: expected + - * / (powers are `powi(x, k)` or `x.powi(k)`)",
            )
        }
    })
}

fn call(a: &mut Arena, scope: &Scope, c: &syn::ExprCall) -> syn::Result<Id> {
    let Expr::Path(p) = &*c.func else {
        return err(&c.func, "expected a function name");
    };
    let Some(f) = p.path.get_ident() else {
        return err(&c.func, "expected a function name");
    };
    let args: Vec<&Expr> = c.args.iter().collect();
    apply(a, scope, f, &args, c)
}

fn method(a: &mut Arena, scope: &Scope, m: &syn::ExprMethodCall) -> syn::Result<Id> {
    let mut args: Vec<&Expr> = vec![&m.receiver];
    args.extend(m.args.iter());
    apply(a, scope, &m.method, &args, m)
}

fn apply(
    a: &mut Arena,
    scope: &Scope,
    f: &syn::Ident,
    args: &[&Expr],
    whole: &impl Spanned,
) -> syn::Result<Id> {
    let name = f.to_string();
    match (name.as_str(), args.len()) {
        ("powi", 2) => {
            let x = convert(a, scope, args[0])?;
            let k = match args[1] {
                Expr::Lit(syn::ExprLit { lit: Lit::Int(i), .. }) => i.base10_parse::<i32>()?,
                Expr::Unary(u) if matches!(u.op, UnOp::Neg(_)) => match &*u.expr {
                    Expr::Lit(syn::ExprLit { lit: Lit::Int(i), .. }) => -i.base10_parse::<i32>()?,
                    other => return err(other, "`powi` needs an integer literal exponent"),
                },
                other => return err(other, "`powi` needs an integer literal exponent"),
            };
            Ok(a.powi(x, k))
        }
        ("powf", 2) => {
            let (x, y) = (convert(a, scope, args[0])?, convert(a, scope, args[1])?);
            Ok(a.powf(x, y))
        }
        (_, 1) => match Func::from_name(&name) {
            Some(func) => {
                let x = convert(a, scope, args[0])?;
                Ok(a.func(func, x))
            }
            None => err(f, format!("unknown function `{name}`: expected sqrt, ln, exp, tanh, abs, sign, sin, cos, powi, powf")),
        },
        _ => err(whole, format!("`{name}` with {} arguments: expected sqrt/ln/exp/tanh/abs/sign/sin/cos of one, powi/powf of two", args.len())),
    }
}
