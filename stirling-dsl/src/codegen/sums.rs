//! Reductions over the sections (per-section links seen from their scalar end): the values
//! `S_k = sum_j s_k(j)` computed once per call in one O(n) loop, and the Jacobian entries of a
//! scalar row `f(.., S_k)` by the chain rule, `df/dS_k * ds_k(j)/dx` added for every `j`
//! (an arrow-shaped Jacobian: the scalar row depends on every section).

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::layout::Layout;
use super::rows::Output;
use crate::expr::emit::emit_block;
use crate::expr::{Arena, Id, Sym};

fn sum_ident(k: usize) -> Ident {
    format_ident!("__sum{}", k)
}

/// `let mut __sum0 = 0.0; ..; for j in 0..n { __sum0 += s_0(j); .. }` (empty without sums).
pub fn prologue(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    if lay.sys.sums.is_empty() {
        return TokenStream::new();
    }
    let leaf = |s: Sym| lay.leaf(s);
    let b = emit_block(arena, &lay.sys.sums, &leaf, private);
    let (lets, outs) = (b.lets, b.outputs);
    let ids: Vec<Ident> = (0..outs.len()).map(sum_ident).collect();
    quote! {
        #(let mut #ids: f64 = 0.0;)*
        for j in 0..n {
            let jf = j as f64;
            let _ = jf;
            #(#lets)*
            #(#ids += #outs;)*
        }
    }
}

/// The chain-rule entries of the scalar rows `(row index, expression)` that hold sums.
pub fn jacobian(
    arena: &mut Arena,
    lay: &Layout,
    rows: &[(TokenStream, Id)],
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let mut code = TokenStream::new();
    for (row, id) in rows {
        for s in arena.symbols(*id) {
            let Sym::Sum(k) = s else { continue };
            let d = arena.diff(*id, s);
            if arena.as_const(d) == Some(0.0) {
                continue;
            }
            code.extend(one_sum(
                arena,
                lay,
                row,
                d,
                lay.sys.sums[k as usize],
                what,
                private,
            ));
        }
    }
    code
}

/// `{ let __d = df/dS; for j in 0..n { sink.add(row, col, __d * ds(j)/dcol); .. } }`.
fn one_sum(
    arena: &mut Arena,
    lay: &Layout,
    row: &TokenStream,
    d: Id,
    template: Id,
    what: Output,
    private: &TokenStream,
) -> TokenStream {
    let (mut cols, mut roots) = (Vec::new(), Vec::new());
    for s in arena.symbols(template) {
        let col = match (what, s) {
            (Output::StateJacobian, Sym::State(b, at)) => lay.index(b, at),
            (Output::ParamJacobian, Sym::Param(k)) => {
                let k = Literal::u32_unsuffixed(k);
                quote!(#k)
            }
            _ => continue,
        };
        let ds = arena.diff(template, s);
        if arena.as_const(ds) != Some(0.0) {
            cols.push(col);
            roots.push(ds);
        }
    }
    let leaf = |s: Sym| lay.leaf(s);
    let outer = emit_block(arena, &[d], &leaf, private);
    let inner = emit_block(arena, &roots, &leaf, private);
    let (olets, dout) = (outer.lets, &outer.outputs[0]);
    let (ilets, outs) = (inner.lets, inner.outputs);
    quote! {
        {
            #(#olets)*
            let __d: f64 = #dout;
            for j in 0..n {
                let jf = j as f64;
                let _ = jf;
                #(#ilets)*
                #(sink.add(#row, #cols, __d * (#outs));)*
            }
        }
    }
}
