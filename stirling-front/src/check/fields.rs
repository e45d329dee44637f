//! The fields of an item: known ones split out, unknown or repeated ones errors,
//! required and optional values converted.

use std::collections::HashMap;

use proc_macro2::Span;
use stirling_dsl::expr::Id;

use super::Lower;
use crate::ast::Field;

impl Lower {
    /// Split fields into the known ones; unknown or repeated fields are errors.
    pub(crate) fn fields<'f>(
        &mut self,
        fields: &'f [Field],
        known: &[&str],
        what: &str,
    ) -> HashMap<String, &'f Field> {
        let mut out = HashMap::new();
        for f in fields {
            let key = f.name.to_string();
            if !known.contains(&key.as_str()) {
                self.cx.error(
                    f.name.span(),
                    format!(
                        "unknown field `{key}` in {what}: expected one of {}",
                        known.join(", ")
                    ),
                );
            } else if out.insert(key.clone(), f).is_some() {
                self.cx.error(
                    f.name.span(),
                    format!("field `{key}` given twice in {what}"),
                );
            }
        }
        out
    }

    pub(crate) fn required(
        &mut self,
        f: &HashMap<String, &Field>,
        key: &str,
        span: Span,
        what: &str,
        index: Option<&str>,
    ) -> Id {
        match f.get(key) {
            Some(field) => self.expr(&field.value, index),
            None => {
                self.cx.error(
                    span,
                    format!("{what} has no `{key}`: expected `{key}: <expression>`"),
                );
                self.topo.arena.num(1.0)
            }
        }
    }

    pub(crate) fn optional(
        &mut self,
        f: &HashMap<String, &Field>,
        key: &str,
        index: Option<&str>,
    ) -> Option<Id> {
        f.get(key).map(|field| self.expr(&field.value, index))
    }
}
