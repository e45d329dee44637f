//! Expansion: a declaration into a model's Rust, a base's `macro_rules!`, or the call into the
//! base's macro that a declaration with `extends` becomes.

use proc_macro2::{Ident, TokenStream};
use quote::{quote, quote_spanned, ToTokens};
use stirling_dsl::codegen::{generate, ModelSpec};
use stirling_front::ast::ModelAst;
use stirling_front::compose::{self, path_span, Decl, Extends, Items};
use syn::{Attribute, Visibility};

/// Expand a declaration: a model, a base's macro, or the call into a base's macro.
///
/// `model X extends path { .. }` expands to `path! { <the whole declaration> }`; the base
/// macro calls `stirling_model!` back with `@base name { <items> }` in front, and the two
/// bodies are merged (`stirling_front::compose::merge`) before the merged model is expanded.
pub fn declaration(decl: Decl) -> syn::Result<TokenStream> {
    let items = match (&decl.extends, &decl.base) {
        (Some(Extends::File(path)), _) => {
            let msg = "`extends \"FILE\"` is read by the file loader (`stirling info FILE.stirling`); in Rust, extend a base by its path";
            return Err(syn::Error::new(path.span(), msg));
        }
        // `extends` not yet resolved: let the base macro put its items in front
        (Some(Extends::Path(path)), None) => {
            let written = &decl.written;
            let bang = quote_spanned!(path_span(path)=> !);
            return Ok(quote!(#path #bang { #written }));
        }
        (Some(_), Some((base, items))) => compose::merge(base, items.clone(), decl.body.clone())?,
        (None, Some((base, _))) => {
            return Err(syn::Error::new(
                base.span(),
                "`@base` is put in front by a base's macro for a declaration with `extends`",
            ))
        }
        (None, None) if !decl.is_base() => {
            return expand(syn::parse2(decl.written)?);
        }
        (None, None) => compose::items(decl.body.clone())?,
    };
    if decl.is_base() {
        return Ok(base_macro(&decl.attrs, &decl.vis, &decl.ident, &items));
    }
    expand(compose::model(&decl, &items)?)
}

/// The whole expansion of one model.
pub fn expand(ast: ModelAst) -> syn::Result<TokenStream> {
    let spec = ModelSpec {
        ident: ast.ident.clone(),
        vis: ast.vis.to_token_stream(),
        krate: quote!(::stirling_dsl),
    };
    Ok(generate(stirling_front::lower(ast)?, &spec))
}

/// `macro_rules! name` re-emitting the base's items in front of whatever it is given.
fn base_macro(attrs: &[Attribute], vis: &Visibility, ident: &Ident, items: &Items) -> TokenStream {
    let exported = matches!(vis, Visibility::Public(_));
    // An exported base calls back through its own crate's root (`$crate::stirling_model`, so
    // a crate exporting a base re-exports the macro at its root); a crate-local one through
    // the name in scope where it is extended.
    let (export, callback) = if exported {
        (quote!(#[macro_export]), quote!($crate::stirling_model))
    } else {
        (quote!(#[allow(unused_macros)]), quote!(stirling_model))
    };
    quote! {
        #(#attrs)*
        #export
        macro_rules! #ident {
            ($($rest:tt)*) => {
                #callback! { @base #ident { #items } $($rest)* }
            };
        }
    }
}
