//! `modify <kind> <name> { fields }`: fields set in place or appended, faces merged body by
//! body, ports replaced by name.

use proc_macro2::{Delimiter, Group, Punct, Spacing, TokenStream, TokenTree};

use super::body::split_commas;

pub(super) fn field_key(ts: &TokenStream) -> String {
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
pub(super) fn modify(tokens: TokenStream, changes: Group) -> TokenStream {
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

pub(super) fn merge_fields(base: TokenStream, changes: TokenStream, nested: bool) -> TokenStream {
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
pub(super) fn merge_group_field(base: &TokenStream, change: &TokenStream) -> TokenStream {
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
