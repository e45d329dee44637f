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
//! How a base's items reach the merge is the caller's business: the `stirling_model!` macro
//! turns a base into a `macro_rules!` that calls the macro back with `@base name { <items> }`
//! in front of the derived declaration; the file loader ([`crate::load`]) reads the base's
//! file (or a built-in base's text) and hands its items over directly. Either way [`merge`]
//! merges the two bodies, token by token, before the merged model is parsed ([`model`]),
//! checked and lowered like any other: an extended model is an ordinary declaration by the
//! time it is lowered.
//!
//! The merge keeps the base's item order (a replaced or modified item stays where it was,
//! so the states keep their order) and appends added items at the end. A base's `name` is
//! not inherited. Items are identified by their names: parameters one by one, `let`s, bodies,
//! couplings by their two bodies, spaces/CVs/walls in one namespace (a `cv` may replace a
//! `space`), the `gas` item, and links by their two ends.

use proc_macro2::{Span, TokenStream};
use quote::{quote, ToTokens};
use syn::parse::{ParseStream, Parser};
use syn::{Attribute, Ident, LitStr, Token, Visibility};

use crate::ast::ModelAst;

mod body;
mod find;
mod items;
mod merge;
mod modify;
mod ops;

use items::Entry;

/// What a declaration extends.
pub enum Extends {
    /// A base by name or path (`default_engine`, `stirling::models::default_engine`).
    Path(syn::Path),
    /// Another file, by a path relative to the declaring file (`"gamma_base.stirling"`): read
    /// by the file loader only.
    File(LitStr),
}

/// The top-level declaration.
pub struct Decl {
    /// `@base name { items }` put in front by a base macro.
    pub base: Option<(Ident, TokenStream)>,
    pub attrs: Vec<Attribute>,
    pub vis: Visibility,
    /// `model` or `base`.
    pub kind: Ident,
    pub ident: Ident,
    pub extends: Option<Extends>,
    pub body: TokenStream,
    /// The declaration as written (without the `@base` part), forwarded to the base macro.
    pub written: TokenStream,
}

impl Decl {
    /// Whether it declares a base (`base name { .. }`) rather than a model.
    pub fn is_base(&self) -> bool {
        self.kind == "base"
    }
}

/// The items of a body (its own, or a base's merged with a derived body's changes), in order.
pub struct Items(Vec<Entry>);

impl ToTokens for Items {
    fn to_tokens(&self, out: &mut TokenStream) {
        self.0.iter().for_each(|e| e.to_tokens(out));
    }
}

pub(super) fn is_ident(input: ParseStream, word: &str) -> bool {
    input.fork().parse::<Ident>().is_ok_and(|i| i == word)
}

/// Parse a declaration: `[@base name { .. }] /// doc  vis (model|base) Name [extends path] { .. }`
/// (`extends "file.stirling"` in a file).
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
            Some(if input.peek(LitStr) {
                Extends::File(input.parse()?)
            } else {
                Extends::Path(input.call(syn::Path::parse_mod_style)?)
            })
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

/// The items of a body that extends nothing, keyed for a merge.
pub fn items(body: TokenStream) -> syn::Result<Items> {
    body::chunks(body).map(Items)
}

/// The items of `base` (its body `base_items`, without its `name`) with the changes of the
/// derived body `body` applied (errors collected, all reported at once).
pub fn merge(base: &Ident, base_items: TokenStream, body: TokenStream) -> syn::Result<Items> {
    merge::merge(base, base_items, body).map(Items)
}

/// The model `Name` of `items`, parsed.
pub fn model(decl: &Decl, items: &Items) -> syn::Result<ModelAst> {
    let (attrs, vis, ident) = (&decl.attrs, &decl.vis, &decl.ident);
    syn::parse2(quote!(#(#attrs)* #vis model #ident { #items }))
}

/// The span of a path's last segment (where an unknown base is reported).
pub fn path_span(path: &syn::Path) -> Span {
    path.segments
        .last()
        .map(|s| s.ident.span())
        .unwrap_or_else(Span::call_site)
}
