//! Effects on a CV's heat port (`effect heater_input on port hot.hot;`): the port's fixed wall
//! temperature `E` becomes a wall with a temperature state, of inverse heat capacity `k` (its
//! null 0: an infinite capacity, the wall frozen at its rest `E`, the fixed wall exactly).
//!
//! - `heater_input` (a single CV's port): wall `<cv>_<port>` held at `E` through a
//!   conductance `G` from a fixed source at `E` (`C T' = Q_gas + G (E - T)`: a heater head of
//!   finite capacity and finite input, which sags by `Q / G` under the heat the gas draws);
//! - `matrix_capacity` (an array's port, `E` a profile in the section index `j`): walls
//!   `<cv>_<port>[n]` of capacity `1 / (k n)` each, with axial conduction `G n` between
//!   sections and `2 G n` to the profile's ends (`E` at `j = -1/2` and `j = n - 1/2`): a
//!   regenerator matrix of finite heat capacity.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};
use syn::{Expr, Ident};

use crate::ast::{Item, ModelAst};

/// Which port effect.
#[derive(Clone, Copy)]
pub enum PortShape {
    /// A single CV's port: a heater head.
    Head,
    /// An array's port: a matrix with axial conduction.
    Matrix,
}

/// Replace the port's fixed wall temperature by the wall, and return the items the wall
/// needs (its declaration, its source temperatures, its conduction links), in order.
pub fn on_port(
    ast: &mut ModelAst,
    kind: &str,
    shape: PortShape,
    (cv, port): (&Ident, &Ident),
    (k, g): (&Ident, &Ident),
) -> syn::Result<Vec<Item>> {
    let site = format!("port {cv}.{port}");
    let err = |span: proc_macro2::Span, msg: String| syn::Error::new(span, msg);
    let wall = format_ident!("{}_{}", cv, port, span = port.span());
    let walls = wall_names(ast);
    if walls.contains(&wall) {
        let msg = format!("effect `{kind}` on {site}: a wall `{wall}` exists already");
        return Err(err(port.span(), msg));
    }
    let Some(v) = ast.items.iter_mut().find_map(|it| match it {
        Item::Cv(v) if v.name == *cv => Some(v),
        _ => None,
    }) else {
        let msg =
            format!("effect `{kind}` on {site}: no cv `{cv}`; it acts on a port of a declared cv");
        return Err(err(cv.span(), msg));
    };
    let count = match (shape, &v.array) {
        (PortShape::Head, None) => None,
        (PortShape::Matrix, Some(n)) => Some(n.clone()),
        (PortShape::Head, Some(_)) => {
            let msg = format!("effect `{kind}` on {site}: `{cv}` is an array of CVs; its ports take `matrix_capacity`");
            return Err(err(cv.span(), msg));
        }
        (PortShape::Matrix, None) => {
            let msg = format!(
                "effect `{kind}` on {site}: `{cv}` is a single CV; its ports take `heater_input`"
            );
            return Err(err(cv.span(), msg));
        }
    };
    let ports: Vec<String> = v.ports.iter().map(|p| p.name.to_string()).collect();
    let Some(p) = v.ports.iter_mut().find(|p| p.name == *port) else {
        let msg = format!(
            "effect `{kind}` on {site}: `{cv}` has no port `{port}` (its ports: {})",
            ports.join(", ")
        );
        return Err(err(port.span(), msg));
    };
    let Some(field) = p.fields.iter_mut().find(|f| f.name == "wall") else {
        let msg = format!("effect `{kind}` on {site}: the port has no `wall:`");
        return Err(err(port.span(), msg));
    };
    if names_a_wall(&field.value, &walls) {
        let msg = format!("effect `{kind}` on {site}: the port's wall is a declared wall already (the effect replaces a fixed temperature)");
        return Err(err(port.span(), msg));
    }
    let rest = field.value.clone();
    field.value = match &count {
        None => syn::parse_quote!(#wall),
        Some(_) => syn::parse_quote!(#wall[j]),
    };
    let tokens = match count {
        None => head(&wall, &rest, k, g),
        Some(n) => matrix(&wall, &rest, &n, k, g),
    };
    tokens
        .into_iter()
        .map(|t| syn::parse::Parser::parse2(crate::ast::item, t))
        .collect()
}

/// The heater head: its wall and the conduction from a source at `rest`.
fn head(wall: &Ident, rest: &Expr, k: &Ident, g: &Ident) -> Vec<TokenStream> {
    let mut out = Vec::new();
    let source = match rest {
        Expr::Path(p) if p.path.get_ident().is_some() => {
            p.path.get_ident().cloned().expect("checked")
        }
        _ => {
            let t = format_ident!("T_{}", wall);
            out.push(quote!(let #t = #rest;));
            t
        }
    };
    out.push(quote!(wall #wall { capacity: 1.0 / #k, rest: #rest }));
    out.push(quote!(link #source -> #wall { conductance: #g }));
    out
}

/// The matrix: `n` walls on the profile `rest`, axial conduction between them and to the
/// profile's ends.
fn matrix(wall: &Ident, rest: &Expr, n: &Ident, k: &Ident, g: &Ident) -> Vec<TokenStream> {
    let (first, last) = (
        format_ident!("T_{}_first", wall),
        format_ident!("T_{}_last", wall),
    );
    let at_first = substitute(rest, &syn::parse_quote!((-0.5)));
    let at_last = substitute(rest, &syn::parse_quote!((#n - 0.5)));
    vec![
        quote!(let #first = #at_first;),
        quote!(let #last = #at_last;),
        quote!(wall #wall[#n] { capacity: 1.0 / (#k * #n), rest: #rest }),
        quote!(link #wall[j] -> #wall[j + 1] for j in 0..#n - 1 { conductance: #g * #n }),
        quote!(link #first -> #wall[0] { conductance: 2.0 * #g * #n }),
        quote!(link #wall[#n - 1] -> #last { conductance: 2.0 * #g * #n }),
    ]
}

/// `e` with the section index `j` replaced by `by`.
fn substitute(e: &Expr, by: &Expr) -> Expr {
    let mut e = e.clone();
    replace_j(&mut e, by);
    e
}

fn replace_j(e: &mut Expr, by: &Expr) {
    match e {
        Expr::Path(p) if p.path.is_ident("j") => *e = by.clone(),
        Expr::Binary(b) => {
            replace_j(&mut b.left, by);
            replace_j(&mut b.right, by);
        }
        Expr::Unary(u) => replace_j(&mut u.expr, by),
        Expr::Paren(p) => replace_j(&mut p.expr, by),
        Expr::Group(g) => replace_j(&mut g.expr, by),
        Expr::Call(c) => c.args.iter_mut().for_each(|a| replace_j(a, by)),
        Expr::MethodCall(m) => {
            replace_j(&mut m.receiver, by);
            m.args.iter_mut().for_each(|a| replace_j(a, by));
        }
        _ => {}
    }
}

fn wall_names(ast: &ModelAst) -> Vec<Ident> {
    ast.items
        .iter()
        .filter_map(|it| match it {
            Item::Wall(w) => Some(w.name.clone()),
            _ => None,
        })
        .collect()
}

/// Whether a port's `wall:` names a declared wall (`head`, `matrix[j]`).
fn names_a_wall(e: &Expr, walls: &[Ident]) -> bool {
    let id = match e {
        Expr::Path(p) => p.path.get_ident(),
        Expr::Index(ix) => match &*ix.expr {
            Expr::Path(p) => p.path.get_ident(),
            _ => None,
        },
        _ => None,
    };
    id.is_some_and(|i| walls.contains(i))
}
