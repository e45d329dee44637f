//! Composition: bases, `extends`, and the merge of a base's items with a derived body.
//!
//! ```text
//! /// docs
//! pub base default_engine { params { .. } gas { .. } body .. space bounce { .. } }
//! pub base nsection_engine extends default_engine { cv hot { .. } .. }
//! pub model AlternatorEngine extends nsection_engine {
//!     params { c_alt: 6.0 "N s/m" }                 // added (a clash is an error)
//!     replace params { bp: 1.9083 "N s/m" }         // a parameter's default, in place
//!     remove param Pb;                              // remove param / let / body / cv / link ..
//!     modify body piston { force: -c_alt * w }      // fields set or appended
//!     replace cv bounce { volume: Vb0, .. }          // the item of that name, in place
//!     cv extra { .. }                               // added at the end
//! }
//! ```
//!
//! A base declares no model: it expands to a `macro_rules!` of its name (`#[macro_export]`
//! when `pub`) whose body holds the base's item tokens. `model X extends path { .. }` expands
//! to `path! { <the whole declaration> }`; the base macro calls `stirling_model!` back with
//! `@base name { <items> }` in front, and this module merges the two bodies, token by token,
//! before the merged model is parsed, checked and expanded like any other. Nothing happens at
//! run time: an extended model is an ordinary declaration by the time it is lowered.
//!
//! The merge keeps the base's item order (a replaced or modified item stays where it was,
//! so the states keep their order) and appends added items at the end. A base's `name` is
//! not inherited. Items are identified by their names: parameters one by one, `let`s, bodies,
//! couplings by their two bodies, spaces/CVs/walls in one namespace (a `cv` may replace a
//! `space`), the `gas` item, and links by their two ends.

use proc_macro2::{Span, TokenStream};
use quote::{quote, quote_spanned};
use syn::parse::{ParseStream, Parser};
use syn::{Attribute, Ident, Token, Visibility};

use crate::ast::ModelAst;

mod body;
pub(crate) use body::end_str;
mod find;
mod items;
mod merge;
mod modify;
mod ops;

use items::Entry;
/// The top-level declaration.
pub struct Decl {
    /// `@base name { items }` put in front by a base macro.
    base: Option<(Ident, TokenStream)>,
    attrs: Vec<Attribute>,
    vis: Visibility,
    /// `model` or `base`.
    kind: Ident,
    ident: Ident,
    extends: Option<syn::Path>,
    body: TokenStream,
    /// The declaration as written (without the `@base` part), forwarded to the base macro.
    written: TokenStream,
}

pub(super) fn is_ident(input: ParseStream, word: &str) -> bool {
    input.fork().parse::<Ident>().is_ok_and(|i| i == word)
}

/// Parse a declaration: `[@base name { .. }] /// doc  vis (model|base) Name [extends path] { .. }`.
pub fn parse(tokens: TokenStream) -> syn::Result<Decl> {
    let parser = |input: ParseStream| -> syn::Result<Decl> {
        let base = if input.peek(Token![@]) {
            input.parse::<Token![@]>()?;
            let kw: Ident = input.parse()?;
            if kw != "base" {
                return Err(syn::Error::new(kw.span(), "expected `@base`"));
            }
            let name: Ident = input.parse()?;
            let content;
            syn::braced!(content in input);
            Some((name, content.parse::<TokenStream>()?))
        } else {
            None
        };
        let written: TokenStream = input.fork().parse()?;
        let attrs = input.call(Attribute::parse_outer)?;
        let vis = input.parse()?;
        let kind: Ident = input.parse()?;
        if kind != "model" && kind != "base" {
            return Err(syn::Error::new(
                kind.span(),
                format!("expected `model Name {{ .. }}` or `base name {{ .. }}`, found `{kind}`"),
            ));
        }
        let ident = input.parse()?;
        let extends = if is_ident(input, "extends") {
            input.parse::<Ident>()?;
            Some(input.call(syn::Path::parse_mod_style)?)
        } else {
            None
        };
        let content;
        syn::braced!(content in input);
        let body = content.parse()?;
        Ok(Decl {
            base,
            attrs,
            vis,
            kind,
            ident,
            extends,
            body,
            written,
        })
    };
    parser.parse2(tokens)
}

/// Expand a declaration: a model, a base's macro, or the call into a base's macro.
pub fn expand(decl: Decl) -> syn::Result<TokenStream> {
    let items = match (&decl.extends, &decl.base) {
        // `extends` not yet resolved: let the base macro put its items in front
        (Some(path), None) => {
            let written = &decl.written;
            let bang = quote_spanned!(path_span(path)=> !);
            return Ok(quote!(#path #bang { #written }));
        }
        (Some(_), Some((base, items))) => merge::merge(base, items.clone(), decl.body.clone())?,
        (None, Some((base, _))) => {
            return Err(syn::Error::new(
                base.span(),
                "`@base` is put in front by a base's macro for a declaration with `extends`",
            ))
        }
        (None, None) if decl.kind == "model" => {
            return crate::expand::expand(syn::parse2(decl.written)?);
        }
        (None, None) => body::chunks(decl.body.clone())?,
    };
    let Decl {
        attrs,
        vis,
        kind,
        ident,
        ..
    } = decl;
    if kind == "base" {
        return Ok(base_macro(&attrs, &vis, &ident, &items));
    }
    let model = quote!(#(#attrs)* #vis model #ident { #(#items)* });
    let ast: ModelAst = syn::parse2(model)?;
    crate::expand::expand(ast)
}

fn path_span(path: &syn::Path) -> Span {
    path.segments
        .last()
        .map(|s| s.ident.span())
        .unwrap_or_else(Span::call_site)
}

/// `macro_rules! name` re-emitting the base's items in front of whatever it is given.
fn base_macro(
    attrs: &[Attribute],
    vis: &Visibility,
    ident: &Ident,
    items: &[Entry],
) -> TokenStream {
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
                #callback! { @base #ident { #(#items)* } $($rest)* }
            };
        }
    }
}
