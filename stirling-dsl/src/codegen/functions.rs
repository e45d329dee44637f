//! The generated functions of one closure (`__rhs_full`, `__jac_full`, ...).

use std::collections::HashSet;

use proc_macro2::{Ident, TokenStream, TokenTree};
use quote::{format_ident, quote};

use super::layout::Layout;
use super::rows::{rows_body, Output};
use super::terms;
use crate::expr::Arena;

/// Wrap `body` into a method with the prologue it reads: `n`, one bounds check of the
/// parameter slice, the parameters and block offsets that occur in `body`.
fn method(
    name: &Ident,
    generics: TokenStream,
    args: TokenStream,
    ret: TokenStream,
    lay: &Layout,
    body: TokenStream,
) -> TokenStream {
    let mut used = HashSet::new();
    idents(&body, &mut used);
    let (params, offsets, slices) = (lay.params(&used), lay.offsets(&used), lay.slices(&used));
    let nf = used.contains("nf").then(|| quote!(let nf = n as f64;));
    quote! {
        #[allow(non_snake_case, unused_variables, unused_parens, unused_assignments, clippy::all)]
        #[inline(never)]
        fn #name #generics(&self, #args) #ret {
            let n: usize = self.n;
            #nf
            #params
            #offsets
            #slices
            #body
        }
    }
}

/// Every identifier in `ts`.
fn idents(ts: &TokenStream, out: &mut HashSet<String>) {
    for tt in ts.clone() {
        match tt {
            TokenTree::Ident(i) => {
                out.insert(i.to_string());
            }
            TokenTree::Group(g) => idents(&g.stream(), out),
            _ => {}
        }
    }
}

/// All methods for the closure `tag` (`full` or `frozen`).
pub fn closure_methods(
    arena: &mut Arena,
    lay: &Layout,
    tag: &str,
    private: &TokenStream,
    krate: &TokenStream,
) -> TokenStream {
    let f = |what: &str| format_ident!("__{}_{}", what, tag);
    let sink = quote!(sink: &mut #krate::JacSink);
    // the Jacobian writes to any writer: triplets or dense (`JacSink`), or values alone
    let writer = quote!(<W: #krate::JacWrite>);
    let wsink = quote!(sink: &mut W);
    let xp = quote!(p: &[f64], x: &[f64]);
    // the sums over the sections, for every function of the state
    let s = super::sums::prologue(arena, lay, private);
    let rhs = rows_body(arena, lay, &lay.sys.rows, &[Output::Value], private);
    let jac = rows_body(arena, lay, &lay.sys.rows, &[Output::StateJacobian], private);
    let pjac = rows_body(arena, lay, &lay.sys.rows, &[Output::ParamJacobian], private);
    let both = [Output::Value, Output::StateJacobian];
    let both = rows_body(arena, lay, &lay.sys.rows, &both, private);
    let forces = terms::forces(arena, lay, private);
    let grads = terms::force_gradients(arena, lay, private);
    let init = terms::init(arena, lay, private);
    let vessels = terms::vessels(arena, lay, private);
    let mech = terms::mech(arena, lay, private);
    let [rhs, jac, both, pjac, forces, grads, vessels, mech] =
        [rhs, jac, both, pjac, forces, grads, vessels, mech].map(|b| quote!(#s #b));
    let masses = terms::masses(arena, lay, private);
    let n_states = n_states(lay);
    let items = [
        method(
            &f("rhs"),
            quote!(),
            quote!(#xp, t: f64, out: &mut [f64]),
            quote!(),
            lay,
            rhs,
        ),
        method(
            &f("jac"),
            writer.clone(),
            quote!(#xp, t: f64, #wsink),
            quote!(),
            lay,
            jac,
        ),
        method(
            &f("rhs_jac"),
            writer,
            quote!(#xp, t: f64, out: &mut [f64], #wsink),
            quote!(),
            lay,
            both,
        ),
        method(
            &f("pjac"),
            quote!(),
            quote!(#xp, t: f64, #sink),
            quote!(),
            lay,
            pjac,
        ),
        method(
            &f("forces"),
            quote!(),
            quote!(#xp, out: &mut [f64]),
            quote!(),
            lay,
            forces,
        ),
        method(
            &f("force_grad"),
            quote!(),
            quote!(__body: usize, #xp, out: &mut [f64]),
            quote!(),
            lay,
            grads,
        ),
        method(
            &f("init"),
            quote!(),
            quote!(p: &[f64], out: &mut [f64]),
            quote!(),
            lay,
            init,
        ),
        method(
            &f("vessels"),
            quote!(),
            quote!(#xp, f: &mut dyn FnMut(usize, [f64; 7])),
            quote!(),
            lay,
            vessels,
        ),
        method(
            &f("mech"),
            quote!(),
            quote!(#xp),
            quote!(-> [f64; 2]),
            lay,
            mech,
        ),
        method(
            &f("masses"),
            quote!(),
            quote!(p: &[f64], out: &mut [f64]),
            quote!(),
            lay,
            masses,
        ),
    ];
    let ns = f("n_states");
    let walls = (!lay.topo.walls.is_empty()).then(|| {
        let body = terms::walls(arena, lay, private);
        let body = quote!(#s #body);
        method(
            &f("walls"),
            quote!(),
            xp.clone(),
            quote!(-> [f64; 2]),
            lay,
            body,
        )
    });
    let items = quote! {
        #(#items)*
        #walls
        #[allow(clippy::all)]
        fn #ns(&self) -> usize {
            let n: usize = self.n;
            #n_states
        }
    };
    items
}

fn n_states(lay: &Layout) -> TokenStream {
    let s = lay.sys.blocks.iter().filter(|b| !b.array).count();
    let a = lay.sys.blocks.iter().filter(|b| b.array).count();
    quote!(#s + #a * n)
}
