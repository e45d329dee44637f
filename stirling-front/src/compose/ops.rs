//! The changes of a derived body: added items, `replace`, `remove`, `modify`.

use proc_macro2::{Delimiter, Span, TokenStream, TokenTree};
use syn::parse::{ParseStream, Parser};
use syn::{Ident, Token};

use super::body::{entry, link_key};
use super::is_ident;
use super::items::{Key, Op};
use crate::ast::EndAst;

/// The changes of a derived body.
pub(super) fn ops(body: TokenStream) -> syn::Result<Vec<Op>> {
    let parser = |input: ParseStream| -> syn::Result<Vec<Op>> {
        let mut out = Vec::new();
        while !input.is_empty() {
            out.push(op(input)?);
        }
        Ok(out)
    };
    parser.parse2(body)
}

pub(super) fn op(input: ParseStream) -> syn::Result<Op> {
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
        if matches!(
            key,
            Key::Param(_) | Key::Let(_) | Key::Name | Key::Sensor(_) | Key::Free
        ) {
            return Err(syn::Error::new(
                span,
                "`modify` changes the fields of a body, coupling, space, cv, wall, link or gas; write `replace params { .. }`, `replace let .. ;` or `replace sensor .. ;`",
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
pub(super) fn target(input: ParseStream, verb: &str) -> syn::Result<(Key, Span)> {
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
        "free" => (Key::Free, kw.span()),
        "body" | "flywheel" | "crank" | "linkage" => {
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
        "sensor" => {
            let n = named(input)?;
            (Key::Sensor(n.to_string()), n.span())
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
                format!("`{verb} {other}`: expected one of param, let, gas, body, flywheel, crank, linkage, coupling, space, cv, wall, link, sensor, free"),
            ))
        }
    })
}
