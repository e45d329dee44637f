//! The merge of a base's items with a derived body: each change applied in order, errors
//! collected (all reported at once).

use proc_macro2::{Group, Span, TokenStream};
use syn::Ident;

use super::body::chunks;
use super::find::{find, find_one, find_param};
use super::items::{Chunk, Entry, Key, Op, Param};
use super::modify::modify;
use super::ops::ops;

/// The base's items (without its `name`) with the changes of `body` applied.
pub(super) fn merge(
    base: &Ident,
    base_items: TokenStream,
    body: TokenStream,
) -> syn::Result<Vec<Entry>> {
    let items: Vec<Entry> = chunks(base_items)?
        .into_iter()
        .filter(|e| !matches!(e, Entry::Item(c) if c.key == Key::Name))
        .collect();
    let mut m = Merge {
        base,
        items,
        errors: Vec::new(),
    };
    for op in ops(body)? {
        match op {
            Op::Add(Entry::Item(c)) => m.add_item(c),
            Op::Add(Entry::Params(span, ps)) => m.add_params(span, ps),
            Op::Replace(Entry::Item(c)) => m.replace_item(c),
            Op::Replace(Entry::Params(_, ps)) => m.replace_params(ps),
            Op::Remove(key, span) => m.remove(key, span),
            Op::Modify(key, span, group) => m.modify(&key, span, group),
        }
    }
    let mut it = m.errors.into_iter();
    match it.next() {
        None => Ok(m.items),
        Some(mut first) => {
            it.for_each(|e| first.combine(e));
            Err(first)
        }
    }
}

/// The items so far and the errors so far.
struct Merge<'a> {
    base: &'a Ident,
    items: Vec<Entry>,
    errors: Vec<syn::Error>,
}

impl Merge<'_> {
    fn err(&mut self, span: Span, msg: String) {
        self.errors.push(syn::Error::new(span, msg));
    }

    /// An added item: appended, unless the base already declares its name (links and effects
    /// excepted: a link may repeat, and an effect named twice is refused where effects are
    /// applied, `crate::effects`).
    fn add_item(&mut self, c: Chunk) {
        let links = matches!(c.key, Key::Link(..) | Key::Effect(..));
        if !links && c.key != Key::Name && find(&self.items, &c.key).is_some() {
            let base = self.base;
            let msg = format!(
                "{} is already declared by `{base}`: {}",
                c.key.describe(),
                c.key.hint()
            );
            self.err(c.span, msg);
            return;
        }
        self.items.push(Entry::Item(c));
    }

    /// Added parameters: appended, those the base already declares refused.
    fn add_params(&mut self, span: Span, ps: Vec<Param>) {
        let mut fresh = Vec::new();
        for p in ps {
            if find_param(&self.items, &p.name.to_string()).is_some() {
                let msg = format!(
                    "parameter `{}` is already declared by `{}`: {}",
                    p.name,
                    self.base,
                    Key::Param(p.name.to_string()).hint()
                );
                self.err(p.name.span(), msg);
            } else {
                fresh.push(p);
            }
        }
        self.items.push(Entry::Params(span, fresh));
    }

    /// `replace <item>`: in place (a `name` is added).
    fn replace_item(&mut self, c: Chunk) {
        if c.key == Key::Name {
            self.items.push(Entry::Item(c));
            return;
        }
        match find_one(&self.items, &c.key, self.base) {
            Ok(i) => self.items[i] = Entry::Item(c),
            Err(msg) => self.err(c.span, format!("cannot replace: {msg}")),
        }
    }

    /// `replace params { .. }`: each parameter in place.
    fn replace_params(&mut self, ps: Vec<Param>) {
        for p in ps {
            match find_param(&self.items, &p.name.to_string()) {
                Some((i, k)) => {
                    if let Entry::Params(_, list) = &mut self.items[i] {
                        list[k] = p;
                    }
                }
                None => {
                    let msg = format!(
                        "cannot replace: `{}` declares no parameter `{}`",
                        self.base, p.name
                    );
                    self.err(p.name.span(), msg);
                }
            }
        }
    }

    /// `remove <kind> <name>;`.
    fn remove(&mut self, key: Key, span: Span) {
        if let Key::Param(name) = &key {
            match find_param(&self.items, name) {
                Some((i, k)) => {
                    if let Entry::Params(_, list) = &mut self.items[i] {
                        list.remove(k);
                    }
                }
                None => {
                    let msg = format!(
                        "cannot remove: `{}` declares no parameter `{name}`",
                        self.base
                    );
                    self.err(span, msg);
                }
            }
            return;
        }
        match find_one(&self.items, &key, self.base) {
            Ok(i) => {
                self.items.remove(i);
            }
            Err(msg) => self.err(span, format!("cannot remove: {msg}")),
        }
    }

    /// `modify <kind> <name> { fields }`.
    fn modify(&mut self, key: &Key, span: Span, group: Group) {
        match find_one(&self.items, key, self.base) {
            Ok(i) => {
                if let Entry::Item(c) = &mut self.items[i] {
                    c.tokens = modify(c.tokens.clone(), group);
                }
            }
            Err(msg) => self.err(span, format!("cannot modify: {msg}")),
        }
    }
}
