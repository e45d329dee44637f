//! The outputs of expression sensors (`sensor dp: P_cold - P_bounce "Pa";`): the generated
//! `Model::sensor_output` with the output's gradient in the states it reads and in the
//! parameters, and the expression as printed.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use crate::expr::emit::emit_block;
use crate::expr::{Arena, Printer, Style, Sym};
use crate::topology::{SensorExpr, Topology};

/// The expression as text, over the states' and parameters' names.
pub fn text(topo: &Topology, e: &SensorExpr) -> String {
    let namer = |s: Sym| match s {
        Sym::Input(i) => e.reads[i as usize].clone(),
        Sym::Param(k) => topo.params[k as usize].name.clone(),
        other => format!("{other:?}"),
    };
    Printer::new(&topo.arena, Style::Text, &namer).expr(e.value)
}

/// The Rust for a symbol of a sensor's output: the parameter slice and the read values.
fn leaf(s: Sym) -> TokenStream {
    match s {
        Sym::Param(k) => {
            let k = Literal::usize_unsuffixed(k as usize);
            quote!(p[#k])
        }
        Sym::Input(i) => {
            let i = Literal::usize_unsuffixed(i as usize);
            quote!(v[#i])
        }
        other => {
            let msg = format!("a sensor output reads states and parameters only, not {other:?}");
            quote!(compile_error!(#msg))
        }
    }
}

/// One arm of `sensor_output`: the value, its gradient in the reads (`dv`) and in the
/// parameters it names (`dp`).
fn arm(arena: &mut Arena, k: usize, e: &SensorExpr, private: &TokenStream) -> TokenStream {
    let params: Vec<u32> = arena
        .symbols(e.value)
        .into_iter()
        .filter_map(|s| if let Sym::Param(j) = s { Some(j) } else { None })
        .collect::<std::collections::BTreeSet<u32>>()
        .into_iter()
        .collect();
    let mut roots = vec![e.value];
    roots.extend((0..e.reads.len()).map(|i| arena.diff(e.value, Sym::Input(i as u32))));
    roots.extend(params.iter().map(|&j| arena.diff(e.value, Sym::Param(j))));
    let block = emit_block(arena, &roots, &leaf, private);
    let (lets, out) = (&block.lets, &block.outputs);
    let value = &out[0];
    let dv = out[1..=e.reads.len()].iter().enumerate().map(|(i, d)| {
        let i = Literal::usize_unsuffixed(i);
        quote!(dv[#i] = #d;)
    });
    let dp = params.iter().zip(&out[1 + e.reads.len()..]).map(|(&j, d)| {
        let j = Literal::usize_unsuffixed(j as usize);
        quote!(dp[#j] = #d;)
    });
    let k = Literal::usize_unsuffixed(k);
    quote! { #k => { #(#lets)* #(#dv)* #(#dp)* #value } }
}

/// `fn sensor_output` for a model with expression sensors; nothing for one without (the
/// trait's default reads the one state).
pub fn sensor_output(arena: &mut Arena, topo: &Topology, private: &TokenStream) -> TokenStream {
    let arms: Vec<TokenStream> = topo
        .sensors
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.expr.as_ref().map(|e| arm(arena, k, e, private)))
        .collect();
    if arms.is_empty() {
        return TokenStream::new();
    }
    quote! {
        #[allow(non_snake_case, unused_variables, unused_parens, clippy::all)]
        fn sensor_output(&self, k: usize, p: &[f64], v: &[f64], dv: &mut [f64], dp: &mut [f64]) -> f64 {
            match k {
                #(#arms)*
                _ => { dv[0] = 1.0; v[0] }
            }
        }
    }
}
