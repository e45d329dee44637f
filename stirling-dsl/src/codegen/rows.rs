//! The right-hand side, the analytic Jacobian and the parameter Jacobian of one
//! system as Rust: one straight-line block for the scalar rows, and one loop over
//! the sections whose body dispatches on the section's [`Variant`].

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::layout::Layout;
use crate::expr::emit::emit_block;
use crate::expr::{Arena, At, Id, Sym};
use crate::topology::{Row, Variant, VARIANTS};

/// What a generated function computes for each row expression.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Output {
    /// `out[row] = f`.
    Value,
    /// `sink.add(row, col, df/dx_col)`.
    StateJacobian,
    /// `sink.add(row, k, df/dp_k)`.
    ParamJacobian,
}

/// One output line: the value to emit and where it goes.
struct Entry {
    id: Id,
    row: TokenStream,
    col: Option<TokenStream>,
}

/// The body of a generated rhs / Jacobian function (after the prologue).
pub fn rows_body(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[Row],
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let scalar: Vec<(usize, Id)> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            if let Row::Scalar(id) = r {
                Some((i, *id))
            } else {
                None
            }
        })
        .collect();
    let grads = (what != Output::Value && !lay.sys.sums.is_empty()).then(|| {
        let ids: Vec<Id> = scalar.iter().map(|&(_, id)| id).collect();
        super::sums::gradients(arena, lay, &ids, what, private)
    });
    let entries = entries(arena, lay, &scalar, what, false, grads.as_ref());
    let mut scalar_code = grads.as_ref().map(|g| g.code.clone()).unwrap_or_default();
    scalar_code.extend(block(arena, lay, &entries, what, private));
    if grads.is_some() {
        let rows: Vec<(TokenStream, Id)> = scalar
            .iter()
            .map(|&(b, id)| (lay.index(lay.sys.blocks[b].sym, At::Scalar), id))
            .collect();
        scalar_code.extend(super::sums::jacobian(arena, lay, &rows, what, private));
    }
    let arrays: Vec<(usize, [Id; 4])> = rows
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            if let Row::Array(v) = r {
                Some((i, *v))
            } else {
                None
            }
        })
        .collect();
    if arrays.is_empty() {
        return scalar_code;
    }
    let arms = variant_arms(arena, lay, &arrays, what, private);
    quote! {
        { #scalar_code }
        for j in 0..n {
            let jf = j as f64;
            let _ = jf;
            #arms
        }
    }
}

/// Group the variants that give the same expressions and emit one arm per group.
fn variant_arms(
    arena: &mut Arena,
    lay: &Layout,
    arrays: &[(usize, [Id; 4])],
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let mut groups: Vec<(Vec<Variant>, Vec<Id>)> = Vec::new();
    for (k, v) in VARIANTS.iter().enumerate() {
        let ids: Vec<Id> = arrays.iter().map(|(_, r)| r[k]).collect();
        match groups.iter_mut().find(|g| g.1 == ids) {
            Some(g) => g.0.push(*v),
            None => groups.push((vec![*v], ids)),
        }
    }
    let bodies: Vec<TokenStream> = groups
        .iter()
        .map(|(_, ids)| {
            let rows: Vec<(usize, Id)> = arrays
                .iter()
                .zip(ids)
                .map(|((i, _), id)| (*i, *id))
                .collect();
            let entries = entries(arena, lay, &rows, what, true, None);
            block(arena, lay, &entries, what, private)
        })
        .collect();
    if groups.len() == 1 {
        let b = &bodies[0];
        return quote! { #b };
    }
    let arms = groups.iter().zip(&bodies).map(|((vs, _), body)| {
        let pats = vs.iter().map(|v| variant_path(*v, private));
        quote! { #(#pats)|* => { #body } }
    });
    quote! {
        match #private::Variant::of(j, n) {
            #(#arms)*
        }
    }
}

fn variant_path(v: Variant, private: &TokenStream) -> TokenStream {
    match v {
        Variant::Single => quote!(#private::Variant::Single),
        Variant::First => quote!(#private::Variant::First),
        Variant::Interior => quote!(#private::Variant::Interior),
        Variant::Last => quote!(#private::Variant::Last),
    }
}

/// The outputs of `rows` for `what`: values, or nonzero derivatives with their columns.
fn entries(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[(usize, Id)],
    what: Output,
    in_loop: bool,
    sums: Option<&super::sums::SumGradients>,
) -> Vec<Entry> {
    let mut out = Vec::new();
    for &(b, id) in rows {
        let at = if in_loop { At::Rel(0) } else { At::Scalar };
        let row = lay.index(lay.sys.blocks[b].sym, at);
        if what == Output::Value {
            out.push(Entry { id, row, col: None });
            continue;
        }
        let cols = match sums {
            Some(g) => g.row_columns(arena, id),
            None => arena.symbols(id),
        };
        for s in cols {
            let col = match (what, s) {
                (Output::StateJacobian, Sym::State(cb, cat)) => lay.index(cb, cat),
                (Output::ParamJacobian, Sym::Param(k)) => {
                    let k = Literal::u32_unsuffixed(k);
                    quote!(#k)
                }
                _ => continue,
            };
            let mut d = arena.diff(id, s);
            if let Some(g) = sums {
                // the sections' part through the sums: `df/dS_k dS_k/ds`
                d = g.total(arena, id, s, d);
            }
            if arena.as_const(d) != Some(0.0) {
                out.push(Entry {
                    id: d,
                    row: row.clone(),
                    col: Some(col),
                });
            }
        }
    }
    out
}

fn block(
    arena: &Arena,
    lay: &Layout,
    entries: &[Entry],
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let roots: Vec<Id> = entries.iter().map(|e| e.id).collect();
    let leaf = |s: Sym| lay.leaf(s);
    let b = emit_block(arena, &roots, &leaf, private);
    let lets = b.lets;
    let stores = entries.iter().zip(b.outputs).map(|(e, v)| {
        let row = &e.row;
        match (&e.col, what) {
            (None, _) => quote! { out[#row] = #v; },
            (Some(col), _) => quote! { sink.add(#row, #col, #v); },
        }
    });
    quote! { #(#lets)* #(#stores)* }
}
