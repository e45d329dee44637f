//! Expansion: the checked topology through the symbolic core into Rust.

use proc_macro2::TokenStream;
use quote::{quote, ToTokens};
use stirling_dsl::codegen::{generate, ModelSpec};

use crate::ast::ModelAst;
use crate::check::lower;

/// The whole expansion of one `stirling_model!` invocation.
pub fn expand(mut ast: ModelAst) -> syn::Result<TokenStream> {
    let effects = crate::effects::apply(&mut ast)?;
    let mut topo = lower(&ast)?;
    topo.effects = effects;
    let spec = ModelSpec {
        ident: ast.ident.clone(),
        vis: ast.vis.to_token_stream(),
        krate: quote!(::stirling_dsl),
    };
    Ok(generate(topo, &spec))
}
