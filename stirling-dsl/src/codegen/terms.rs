//! Generated helpers besides the rows: pressure forces and their gradients, the
//! equilibrium guess, and per-vessel terms for work, energy and mass reductions.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::layout::Layout;
use super::rows::{rows_body, Output};
use crate::expr::emit::emit_block;
use crate::expr::{Arena, Id, Sym};
use crate::topology::VesselTerms;

/// `out[k] = F_k` for every body.
pub fn forces(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let leaf = |s: Sym| lay.leaf(s);
    let b = emit_block(arena, &lay.sys.forces, &leaf, private);
    let lets = b.lets;
    let stores = b.outputs.iter().enumerate().map(|(k, v)| {
        let k = Literal::usize_unsuffixed(k);
        quote! { out[#k] = #v; }
    });
    quote! { #(#lets)* #(#stores)* }
}

/// `match __body { 0 => { out[col] += dF_0/dx_col; ... } ... }`.
pub fn force_gradients(arena: &mut Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let mut arms = Vec::new();
    for (k, &f) in lay.sys.forces.iter().enumerate() {
        let mut roots = Vec::new();
        let mut cols = Vec::new();
        for s in arena.symbols(f) {
            if let Sym::State(b, at) = s {
                let d = arena.diff(f, s);
                if arena.as_const(d) != Some(0.0) {
                    roots.push(d);
                    cols.push(lay.index(b, at));
                }
            }
        }
        let leaf = |s: Sym| lay.leaf(s);
        let b = emit_block(arena, &roots, &leaf, private);
        let lets = b.lets;
        let stores = cols
            .iter()
            .zip(b.outputs)
            .map(|(c, v)| quote! { out[#c] += #v; });
        let k = Literal::usize_unsuffixed(k);
        arms.push(quote! { #k => { #(#lets)* #(#stores)* } });
    }
    quote! { match __body { #(#arms)* _ => {} } }
}

/// The equilibrium guess as `out[...] = ...` over all blocks.
pub fn init(arena: &mut Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    rows_body(arena, lay, &lay.sys.init, &[Output::Value], private)
}

/// Calls `f(element, [P, V, E, Q, boundary, m, T])` for every vessel element:
/// CV elements in declaration order (arrays expanded), then spaces.
pub fn vessels(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let mut code = TokenStream::new();
    let mut scalar_before = 0usize;
    let mut arrays_before = 0usize;
    for v in &lay.sys.vessels {
        let roots = terms(v);
        let leaf = |s: Sym| lay.leaf(s);
        let b = emit_block(arena, &roots, &leaf, private);
        let (lets, outs) = (b.lets, b.outputs);
        let (s, a) = (
            Literal::usize_unsuffixed(scalar_before),
            Literal::usize_unsuffixed(arrays_before),
        );
        code.extend(if v.array {
            quote! {
                for j in 0..n {
                    let jf = j as f64;
                    let _ = jf;
                    #(#lets)*
                    f(#s + #a * n + j, [#(#outs),*]);
                }
            }
        } else {
            quote! { { #(#lets)* f(#s + #a * n, [#(#outs),*]); } }
        });
        if v.array {
            arrays_before += 1;
        } else {
            scalar_before += 1;
        }
    }
    code
}

fn terms(v: &VesselTerms) -> Vec<Id> {
    vec![
        v.pressure,
        v.volume,
        v.energy,
        v.heat,
        v.boundary,
        v.mass,
        v.temperature,
    ]
}

/// `[mechanical energy, mechanical power]`.
pub fn mech(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let leaf = |s: Sym| lay.leaf(s);
    let b = emit_block(
        arena,
        &[lay.sys.mech_energy, lay.sys.mech_power],
        &leaf,
        private,
    );
    let (lets, outs) = (b.lets, b.outputs);
    quote! { #(#lets)* [#(#outs),*] }
}

/// `out[k] = m_k`, the declared mass of every body (parameters only).
pub fn masses(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let leaf = |s: Sym| lay.leaf(s);
    let roots: Vec<Id> = lay.topo.bodies.iter().map(|b| b.mass).collect();
    let b = emit_block(arena, &roots, &leaf, private);
    let lets = b.lets;
    let stores = b.outputs.iter().enumerate().map(|(k, v)| {
        let k = Literal::usize_unsuffixed(k);
        quote! { out[#k] = #v; }
    });
    quote! { #(#lets)* #(#stores)* }
}

/// `[sum C Tw, heat from outside into the walls]` over every wall element (only for a
/// topology with walls).
pub fn walls(arena: &Arena, lay: &Layout, private: &TokenStream) -> TokenStream {
    let leaf = |s: Sym| lay.leaf(s);
    let scalar: Vec<&crate::topology::WallTerms> =
        lay.sys.walls.iter().filter(|w| !w.array).collect();
    let mut roots = vec![lay.sys.wall_boundary_heat];
    roots.extend(scalar.iter().flat_map(|w| [w.energy, w.heat]));
    let b = emit_block(arena, &roots, &leaf, private);
    let (lets, outs) = (b.lets, b.outputs);
    let (heat0, rest) = (&outs[0], &outs[1..]);
    let (es, hs): (Vec<_>, Vec<_>) = rest.chunks(2).map(|c| (&c[0], &c[1])).unzip();
    let mut code = quote! {
        let mut __e = 0.0f64;
        let mut __q = 0.0f64;
        { #(#lets)* __q += #heat0; #(__e += #es;)* #(__q += #hs;)* }
    };
    for w in lay.sys.walls.iter().filter(|w| w.array) {
        let heated = arena.as_const(w.heat) != Some(0.0);
        let roots = if heated {
            vec![w.energy, w.heat]
        } else {
            vec![w.energy]
        };
        let b = emit_block(arena, &roots, &leaf, private);
        let (lets, outs) = (b.lets, b.outputs);
        let (e, q) = (&outs[0], outs.get(1).map(|q| quote!(__q += #q;)));
        code.extend(quote! {
            for j in 0..n {
                let jf = j as f64;
                let _ = jf;
                #(#lets)*
                __e += #e;
                #q
            }
        });
    }
    quote! { #code [__e, __q] }
}
