//! The items of a body as the merge sees them: keyed chunks of tokens, parameters one by
//! one, and the changes (`Op`) a derived body makes.

use proc_macro2::{Group, Span, TokenStream};
use quote::{quote, ToTokens};
use syn::Ident;

/// What an item is known by in a merge.
#[derive(Clone, PartialEq, Eq)]
pub(super) enum Key {
    Name,
    Gas,
    Let(String),
    Body(String),
    Coupling(String, String),
    /// Space, CV or wall: one namespace.
    Vessel(String),
    /// The two ends as written (`regen [n - 1]`).
    Link(String, String),
    Param(String),
    Sensor(String),
    Free,
    /// An effect and where it acts.
    Effect(String, String),
}

impl Key {
    pub(super) fn describe(&self) -> String {
        match self {
            Key::Name => "`name`".into(),
            Key::Gas => "`gas`".into(),
            Key::Let(n) => format!("let `{n}`"),
            Key::Body(n) => format!("body `{n}`"),
            Key::Coupling(a, b) => format!("coupling `{a}, {b}`"),
            Key::Vessel(n) => format!("space, cv or wall `{n}`"),
            Key::Link(a, b) => format!("link `{a} -> {b}`"),
            Key::Param(n) => format!("parameter `{n}`"),
            Key::Sensor(n) => format!("sensor `{n}`"),
            Key::Free => "`free`".into(),
            Key::Effect(e, at) => format!("`effect {e}` on `{at}`"),
        }
    }

    /// Its name alone, for the lists of what a base declares.
    pub(super) fn short(&self) -> String {
        match self {
            Key::Name => "name".into(),
            Key::Gas => "gas".into(),
            Key::Free => "free".into(),
            Key::Let(n) | Key::Body(n) | Key::Vessel(n) | Key::Param(n) | Key::Sensor(n) => {
                format!("`{n}`")
            }
            Key::Coupling(a, b) => format!("`{a}, {b}`"),
            Key::Link(a, b) => format!("`{a} -> {b}`"),
            Key::Effect(e, at) => format!("`{e}` on `{at}`"),
        }
    }

    /// How to replace or change it, for the hints.
    pub(super) fn hint(&self) -> String {
        let k = self.keyword();
        match self {
            Key::Let(n) => format!("write `replace let {n} = ..;` to replace it"),
            Key::Param(n) => format!("write `replace params {{ {n}: .. }}` to change its default"),
            Key::Sensor(n) => format!("write `replace sensor {n}: STATE \"unit\";` to replace it"),
            _ => format!(
                "write `replace {k} {{ .. }}` to replace it or `modify {k} {{ .. }}` to change its fields"
            ),
        }
    }

    /// How to write a change of it, for the hints.
    pub(super) fn keyword(&self) -> String {
        match self {
            Key::Name => "name".into(),
            Key::Gas => "gas".into(),
            Key::Let(n) => format!("let {n}"),
            Key::Body(n) => format!("body {n}"),
            Key::Coupling(a, b) => format!("coupling {a}, {b}"),
            Key::Vessel(n) => format!("cv {n}"),
            Key::Link(a, b) => format!("link {a} -> {b}"),
            Key::Param(n) => format!("param {n}"),
            Key::Sensor(n) => format!("sensor {n}"),
            Key::Free => "free".into(),
            Key::Effect(e, at) => format!("effect {e} on {at}"),
        }
    }
}

/// One item of a body, as tokens.
#[derive(Clone)]
pub(super) struct Chunk {
    pub(super) key: Key,
    /// The item's name token (for errors).
    pub(super) span: Span,
    pub(super) tokens: TokenStream,
}

/// One parameter of a `params` block, as tokens (docs included).
#[derive(Clone)]
pub(super) struct Param {
    pub(super) name: Ident,
    pub(super) tokens: TokenStream,
}

#[derive(Clone)]
pub(super) enum Entry {
    Item(Chunk),
    Params(Span, Vec<Param>),
}

impl ToTokens for Entry {
    fn to_tokens(&self, out: &mut TokenStream) {
        match self {
            Entry::Item(c) => out.extend(c.tokens.clone()),
            Entry::Params(span, ps) if !ps.is_empty() => {
                let kw = Ident::new("params", *span);
                let list = ps.iter().map(|p| &p.tokens);
                out.extend(quote!(#kw { #(#list,)* }));
            }
            Entry::Params(..) => {}
        }
    }
}

/// A change a derived body makes to its base.
pub(super) enum Op {
    Add(Entry),
    Replace(Entry),
    Remove(Key, Span),
    Modify(Key, Span, Group),
}
