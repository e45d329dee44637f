//! Looking up a base's items by key, with the messages for what is missing.

use syn::Ident;

use super::items::{Entry, Key};

pub(super) fn find(items: &[Entry], key: &Key) -> Option<usize> {
    items
        .iter()
        .position(|e| matches!(e, Entry::Item(c) if &c.key == key))
}

/// The one item of `key`, or why not.
pub(super) fn find_one(items: &[Entry], key: &Key, base: &Ident) -> Result<usize, String> {
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

pub(super) fn find_param(items: &[Entry], name: &str) -> Option<(usize, usize)> {
    items.iter().enumerate().find_map(|(i, e)| match e {
        Entry::Params(_, ps) => ps.iter().position(|p| p.name == name).map(|k| (i, k)),
        _ => None,
    })
}
