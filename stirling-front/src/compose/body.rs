//! A body's tokens split into keyed entries (items, parameters one by one).

use proc_macro2::{Span, TokenStream, TokenTree};
use syn::parse::{ParseStream, Parser};
use syn::Ident;

use super::items::{Chunk, Entry, Key, Param};
use crate::ast::{item, EndAst, Item};

pub(super) fn chunks(body: TokenStream) -> syn::Result<Vec<Entry>> {
    let parser = |input: ParseStream| -> syn::Result<Vec<Entry>> {
        let mut out = Vec::new();
        while !input.is_empty() {
            out.push(entry(input)?);
        }
        Ok(out)
    };
    parser.parse2(body)
}

/// Parse one item and keep its tokens.
pub(super) fn entry(input: ParseStream) -> syn::Result<Entry> {
    let begin = input.cursor();
    let it = item(input)?;
    let end = input.cursor();
    let mut tokens = TokenStream::new();
    let mut c = begin;
    while c != end {
        let Some((tt, next)) = c.token_tree() else {
            break;
        };
        tokens.extend([tt]);
        c = next;
    }
    let (key, span) = match &it {
        Item::Params(_) => return params_entry(tokens),
        Item::Name(s) => (Key::Name, s.span()),
        Item::Let(n, _) => (Key::Let(n.to_string()), n.span()),
        Item::Gas(span, _) => (Key::Gas, *span),
        Item::Body(b) => (Key::Body(b.name.to_string()), b.name.span()),
        Item::Mechanism(m) => (Key::Body(m.name.to_string()), m.name.span()),
        Item::Coupling(c) => (Key::Coupling(c.a.to_string(), c.b.to_string()), c.a.span()),
        Item::Space(v) | Item::Cv(v) | Item::Wall(v) => {
            (Key::Vessel(v.name.to_string()), v.name.span())
        }
        Item::Link(l) => (link_key(&l.from, &l.to), l.from.name.span()),
        Item::Sensor(s) => (Key::Sensor(s.name.to_string()), s.name.span()),
        Item::Free(span, _) => (Key::Free, *span),
        Item::Effect(e) => (Key::Effect(e.kind.to_string(), e.site.describe()), e.span),
    };
    Ok(Entry::Item(Chunk { key, span, tokens }))
}

pub(super) fn link_key(from: &EndAst, to: &EndAst) -> Key {
    Key::Link(from.text(), to.text())
}

/// Split a group's tokens at its top-level commas (empty pieces dropped).
pub(super) fn split_commas(ts: TokenStream) -> Vec<TokenStream> {
    let mut out = Vec::new();
    let mut cur = TokenStream::new();
    for tt in ts {
        match &tt {
            TokenTree::Punct(p) if p.as_char() == ',' => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            _ => cur.extend([tt]),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// The first identifier of a piece, after its attributes (`#[doc = ..]`).
pub(super) fn first_ident(ts: &TokenStream) -> Option<Ident> {
    let mut skip = false;
    for tt in ts.clone() {
        match tt {
            TokenTree::Punct(p) if p.as_char() == '#' => skip = true,
            TokenTree::Group(_) if skip => skip = false,
            TokenTree::Ident(i) => return Some(i),
            _ => return None,
        }
    }
    None
}

/// `params { .. }` as one entry per parameter.
pub(super) fn params_entry(tokens: TokenStream) -> syn::Result<Entry> {
    let mut it = tokens.into_iter();
    let kw = it.next();
    let span = kw.as_ref().map_or_else(Span::call_site, TokenTree::span);
    let Some(TokenTree::Group(g)) = it.next() else {
        return Err(syn::Error::new(span, "expected `params { .. }`"));
    };
    let mut ps = Vec::new();
    for piece in split_commas(g.stream()) {
        let Some(name) = first_ident(&piece) else {
            return Err(syn::Error::new(span, "expected `name: default \"unit\"`"));
        };
        ps.push(Param {
            name,
            tokens: piece,
        });
    }
    Ok(Entry::Params(span, ps))
}
