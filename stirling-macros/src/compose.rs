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

use proc_macro2::{Delimiter, Group, Punct, Spacing, Span, TokenStream, TokenTree};
use quote::{quote, quote_spanned, ToTokens};
use syn::parse::{ParseStream, Parser};
use syn::{Attribute, Ident, Token, Visibility};

use crate::ast::{item, EndAst, Item, ModelAst};

/// What an item is known by in a merge.
#[derive(Clone, PartialEq, Eq)]
enum Key {
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
}

impl Key {
    fn describe(&self) -> String {
        match self {
            Key::Name => "`name`".into(),
            Key::Gas => "`gas`".into(),
            Key::Let(n) => format!("let `{n}`"),
            Key::Body(n) => format!("body `{n}`"),
            Key::Coupling(a, b) => format!("coupling `{a}, {b}`"),
            Key::Vessel(n) => format!("space, cv or wall `{n}`"),
            Key::Link(a, b) => format!("link `{a} -> {b}`"),
            Key::Param(n) => format!("parameter `{n}`"),
        }
    }

    /// Its name alone, for the lists of what a base declares.
    fn short(&self) -> String {
        match self {
            Key::Name => "name".into(),
            Key::Gas => "gas".into(),
            Key::Let(n) | Key::Body(n) | Key::Vessel(n) | Key::Param(n) => format!("`{n}`"),
            Key::Coupling(a, b) => format!("`{a}, {b}`"),
            Key::Link(a, b) => format!("`{a} -> {b}`"),
        }
    }

    /// How to replace or change it, for the hints.
    fn hint(&self) -> String {
        let k = self.keyword();
        match self {
            Key::Let(n) => format!("write `replace let {n} = ..;` to replace it"),
            Key::Param(n) => format!("write `replace params {{ {n}: .. }}` to change its default"),
            _ => format!(
                "write `replace {k} {{ .. }}` to replace it or `modify {k} {{ .. }}` to change its fields"
            ),
        }
    }

    /// How to write a change of it, for the hints.
    fn keyword(&self) -> String {
        match self {
            Key::Name => "name".into(),
            Key::Gas => "gas".into(),
            Key::Let(n) => format!("let {n}"),
            Key::Body(n) => format!("body {n}"),
            Key::Coupling(a, b) => format!("coupling {a}, {b}"),
            Key::Vessel(n) => format!("cv {n}"),
            Key::Link(a, b) => format!("link {a} -> {b}"),
            Key::Param(n) => format!("param {n}"),
        }
    }
}

/// One item of a body, as tokens.
#[derive(Clone)]
struct Chunk {
    key: Key,
    /// The item's name token (for errors).
    span: Span,
    tokens: TokenStream,
}

/// One parameter of a `params` block, as tokens (docs included).
#[derive(Clone)]
struct Param {
    name: Ident,
    tokens: TokenStream,
}

#[derive(Clone)]
enum Entry {
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
enum Op {
    Add(Entry),
    Replace(Entry),
    Remove(Key, Span),
    Modify(Key, Span, Group),
}

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

fn is_ident(input: ParseStream, word: &str) -> bool {
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
        (Some(_), Some((base, items))) => merge(base, items.clone(), decl.body.clone())?,
        (None, Some((base, _))) => {
            return Err(syn::Error::new(
                base.span(),
                "`@base` is put in front by a base's macro for a declaration with `extends`",
            ))
        }
        (None, None) if decl.kind == "model" => {
            return crate::expand::expand(syn::parse2(decl.written)?);
        }
        (None, None) => chunks(decl.body.clone())?,
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

/// The items of a body, each with its tokens.
fn chunks(body: TokenStream) -> syn::Result<Vec<Entry>> {
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
fn entry(input: ParseStream) -> syn::Result<Entry> {
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
        Item::Coupling(c) => (Key::Coupling(c.a.to_string(), c.b.to_string()), c.a.span()),
        Item::Space(v) | Item::Cv(v) | Item::Wall(v) => {
            (Key::Vessel(v.name.to_string()), v.name.span())
        }
        Item::Link(l) => (link_key(&l.from, &l.to), l.from.name.span()),
    };
    Ok(Entry::Item(Chunk { key, span, tokens }))
}

fn end_str(e: &EndAst) -> String {
    match &e.index {
        Some(i) => format!("{}[{}]", e.name, i.to_token_stream()),
        None => e.name.to_string(),
    }
}

fn link_key(from: &EndAst, to: &EndAst) -> Key {
    Key::Link(end_str(from), end_str(to))
}

/// Split a group's tokens at its top-level commas (empty pieces dropped).
fn split_commas(ts: TokenStream) -> Vec<TokenStream> {
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
fn first_ident(ts: &TokenStream) -> Option<Ident> {
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
fn params_entry(tokens: TokenStream) -> syn::Result<Entry> {
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

/// The changes of a derived body.
fn ops(body: TokenStream) -> syn::Result<Vec<Op>> {
    let parser = |input: ParseStream| -> syn::Result<Vec<Op>> {
        let mut out = Vec::new();
        while !input.is_empty() {
            out.push(op(input)?);
        }
        Ok(out)
    };
    parser.parse2(body)
}

fn op(input: ParseStream) -> syn::Result<Op> {
    if is_ident(input, "replace") {
        input.parse::<Ident>()?;
        return Ok(Op::Replace(entry(input)?));
    }
    if is_ident(input, "remove") {
        input.parse::<Ident>()?;
        let (key, span) = target(input, "remove")?;
        input.parse::<Token![;]>()?;
        return Ok(Op::Remove(key, span));
    }
    if is_ident(input, "modify") {
        input.parse::<Ident>()?;
        let (key, span) = target(input, "modify")?;
        if matches!(key, Key::Param(_) | Key::Let(_) | Key::Name) {
            return Err(syn::Error::new(
                span,
                "`modify` changes the fields of a body, coupling, space, cv, wall, link or gas; write `replace params { .. }` or `replace let .. ;`",
            ));
        }
        let TokenTree::Group(g) = input.parse::<TokenTree>()? else {
            return Err(syn::Error::new(span, "expected `{ field: value, .. }`"));
        };
        if g.delimiter() != Delimiter::Brace {
            return Err(syn::Error::new(g.span(), "expected `{ field: value, .. }`"));
        }
        return Ok(Op::Modify(key, span, g));
    }
    Ok(Op::Add(entry(input)?))
}

/// `kind name` (or `link a -> b`, `coupling a, b`, `gas`) naming an item to remove or modify.
fn target(input: ParseStream, verb: &str) -> syn::Result<(Key, Span)> {
    if input.peek(Token![let]) {
        input.parse::<Token![let]>()?;
        let n: Ident = input.parse()?;
        return Ok((Key::Let(n.to_string()), n.span()));
    }
    let kw: Ident = input.parse()?;
    let named = |input: ParseStream| -> syn::Result<Ident> { input.parse() };
    Ok(match kw.to_string().as_str() {
        "param" => {
            let n = named(input)?;
            (Key::Param(n.to_string()), n.span())
        }
        "gas" => (Key::Gas, kw.span()),
        "body" => {
            let n = named(input)?;
            (Key::Body(n.to_string()), n.span())
        }
        "coupling" => {
            let a = named(input)?;
            input.parse::<Token![,]>()?;
            let b = named(input)?;
            (Key::Coupling(a.to_string(), b.to_string()), a.span())
        }
        "space" | "cv" | "wall" => {
            let n = named(input)?;
            (Key::Vessel(n.to_string()), n.span())
        }
        "link" => {
            let from: EndAst = input.parse()?;
            input.parse::<Token![->]>()?;
            let to: EndAst = input.parse()?;
            (link_key(&from, &to), from.name.span())
        }
        other => {
            return Err(syn::Error::new(
                kw.span(),
                format!("`{verb} {other}`: expected one of param, let, gas, body, coupling, space, cv, wall, link"),
            ))
        }
    })
}

/// The base's items with the derived body's changes applied, in order.
fn merge(base: &Ident, base_items: TokenStream, body: TokenStream) -> syn::Result<Vec<Entry>> {
    let mut items: Vec<Entry> = chunks(base_items)?
        .into_iter()
        .filter(|e| !matches!(e, Entry::Item(c) if c.key == Key::Name))
        .collect();
    let mut errors: Vec<syn::Error> = Vec::new();
    let mut err = |span: Span, msg: String| errors.push(syn::Error::new(span, msg));
    for op in ops(body)? {
        match op {
            Op::Add(Entry::Item(c)) => {
                let links = matches!(c.key, Key::Link(..));
                if !links && c.key != Key::Name && find(&items, &c.key).is_some() {
                    err(
                        c.span,
                        format!(
                            "{} is already declared by `{base}`: {}",
                            c.key.describe(),
                            c.key.hint()
                        ),
                    );
                    continue;
                }
                items.push(Entry::Item(c));
            }
            Op::Add(Entry::Params(span, ps)) => {
                let mut fresh = Vec::new();
                for p in ps {
                    if find_param(&items, &p.name.to_string()).is_some() {
                        err(
                            p.name.span(),
                            format!(
                                "parameter `{}` is already declared by `{base}`: {}",
                                p.name,
                                Key::Param(p.name.to_string()).hint()
                            ),
                        );
                    } else {
                        fresh.push(p);
                    }
                }
                items.push(Entry::Params(span, fresh));
            }
            Op::Replace(Entry::Item(c)) => {
                if c.key == Key::Name {
                    items.push(Entry::Item(c));
                    continue;
                }
                match find_one(&items, &c.key, base) {
                    Ok(i) => items[i] = Entry::Item(c),
                    Err(msg) => err(c.span, format!("cannot replace: {msg}")),
                }
            }
            Op::Replace(Entry::Params(_, ps)) => {
                for p in ps {
                    match find_param(&items, &p.name.to_string()) {
                        Some((i, k)) => {
                            if let Entry::Params(_, list) = &mut items[i] {
                                list[k] = p;
                            }
                        }
                        None => err(
                            p.name.span(),
                            format!(
                                "cannot replace: `{base}` declares no parameter `{}`",
                                p.name
                            ),
                        ),
                    }
                }
            }
            Op::Remove(Key::Param(name), span) => match find_param(&items, &name) {
                Some((i, k)) => {
                    if let Entry::Params(_, list) = &mut items[i] {
                        list.remove(k);
                    }
                }
                None => err(
                    span,
                    format!("cannot remove: `{base}` declares no parameter `{name}`"),
                ),
            },
            Op::Remove(key, span) => match find_one(&items, &key, base) {
                Ok(i) => {
                    items.remove(i);
                }
                Err(msg) => err(span, format!("cannot remove: {msg}")),
            },
            Op::Modify(key, span, group) => match find_one(&items, &key, base) {
                Ok(i) => {
                    if let Entry::Item(c) = &mut items[i] {
                        c.tokens = modify(c.tokens.clone(), group);
                    }
                }
                Err(msg) => err(span, format!("cannot modify: {msg}")),
            },
        }
    }
    let mut it = errors.into_iter();
    match it.next() {
        None => Ok(items),
        Some(mut first) => {
            it.for_each(|e| first.combine(e));
            Err(first)
        }
    }
}

fn find(items: &[Entry], key: &Key) -> Option<usize> {
    items
        .iter()
        .position(|e| matches!(e, Entry::Item(c) if &c.key == key))
}

/// The one item of `key`, or why not.
fn find_one(items: &[Entry], key: &Key, base: &Ident) -> Result<usize, String> {
    let hits: Vec<usize> = items
        .iter()
        .enumerate()
        .filter(|(_, e)| matches!(e, Entry::Item(c) if &c.key == key))
        .map(|(i, _)| i)
        .collect();
    match hits.as_slice() {
        [i] => Ok(*i),
        [] => {
            let mut known: Vec<String> = items
                .iter()
                .filter_map(|e| match e {
                    Entry::Item(c)
                        if std::mem::discriminant(&c.key) == std::mem::discriminant(key) =>
                    {
                        Some(c.key.short())
                    }
                    _ => None,
                })
                .collect();
            known.dedup();
            let also = if known.is_empty() {
                String::new()
            } else {
                format!(" (it declares {})", known.join(", "))
            };
            Err(format!("`{base}` declares no {}{also}", key.describe()))
        }
        _ => Err(format!(
            "`{base}` declares {} {} times; remove it and add the links again",
            key.describe(),
            hits.len()
        )),
    }
}

fn find_param(items: &[Entry], name: &str) -> Option<(usize, usize)> {
    items.iter().enumerate().find_map(|(i, e)| match e {
        Entry::Params(_, ps) => ps.iter().position(|p| p.name == name).map(|k| (i, k)),
        _ => None,
    })
}

/// The key of one field of a braced list: `name: ..`, `faces`, `port NAME`.
fn field_key(ts: &TokenStream) -> String {
    let tts: Vec<TokenTree> = ts.clone().into_iter().take(3).collect();
    match tts.as_slice() {
        [TokenTree::Ident(p), TokenTree::Ident(n), TokenTree::Group(_)] if p == "port" => {
            format!("port {n}")
        }
        [TokenTree::Ident(i), ..] => i.to_string(),
        _ => ts.to_string(),
    }
}

/// Set or append the fields of `changes` in the item's last braced group (faces merged by
/// body, ports by name).
fn modify(tokens: TokenStream, changes: Group) -> TokenStream {
    let mut tts: Vec<TokenTree> = tokens.into_iter().collect();
    let Some(pos) = tts
        .iter()
        .rposition(|t| matches!(t, TokenTree::Group(g) if g.delimiter() == Delimiter::Brace))
    else {
        return tts.into_iter().collect();
    };
    let TokenTree::Group(g) = &tts[pos] else {
        unreachable!()
    };
    let merged = merge_fields(g.stream(), changes.stream(), true);
    let mut ng = Group::new(Delimiter::Brace, merged);
    ng.set_span(g.span());
    tts[pos] = TokenTree::Group(ng);
    tts.into_iter().collect()
}

fn merge_fields(base: TokenStream, changes: TokenStream, nested: bool) -> TokenStream {
    let mut fields = split_commas(base);
    for ch in split_commas(changes) {
        let key = field_key(&ch);
        match fields.iter().position(|f| field_key(f) == key) {
            Some(i) if nested && key == "faces" => {
                fields[i] = merge_group_field(&fields[i], &ch);
            }
            Some(i) => fields[i] = ch,
            None => fields.push(ch),
        }
    }
    let mut out = TokenStream::new();
    for (i, f) in fields.into_iter().enumerate() {
        if i > 0 {
            out.extend([TokenTree::Punct(Punct::new(',', Spacing::Alone))]);
        }
        out.extend(f);
    }
    out
}

/// `faces { .. }` merged entry by entry.
fn merge_group_field(base: &TokenStream, change: &TokenStream) -> TokenStream {
    let group = |ts: &TokenStream| {
        ts.clone().into_iter().find_map(|t| match t {
            TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => Some(g),
            _ => None,
        })
    };
    let (Some(b), Some(c)) = (group(base), group(change)) else {
        return change.clone();
    };
    let mut out: Vec<TokenTree> = base.clone().into_iter().collect();
    if let Some(last) = out.last_mut() {
        let mut g = Group::new(
            Delimiter::Brace,
            merge_fields(b.stream(), c.stream(), false),
        );
        g.set_span(b.span());
        *last = TokenTree::Group(g);
    }
    out.into_iter().collect()
}
