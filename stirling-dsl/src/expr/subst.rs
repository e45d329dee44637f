//! Substitution of symbols by expressions.

use std::collections::HashMap;

use super::arena::Arena;
use super::node::{Id, Node, Sym};

impl Arena {
    /// Rebuild `id` with every symbol for which `map` answers replaced; names are kept.
    pub fn subst(&mut self, id: Id, map: &mut dyn FnMut(&mut Arena, Sym) -> Option<Id>) -> Id {
        self.subst_renaming(id, map, &|n| n.to_string())
    }

    /// As [`Arena::subst`], also renaming every named quantity with `rename`.
    pub fn subst_renaming(
        &mut self,
        id: Id,
        map: &mut dyn FnMut(&mut Arena, Sym) -> Option<Id>,
        rename: &dyn Fn(&str) -> String,
    ) -> Id {
        let mut memo = HashMap::new();
        self.subst_memo(id, map, rename, &mut memo)
    }

    fn subst_memo(
        &mut self,
        id: Id,
        map: &mut dyn FnMut(&mut Arena, Sym) -> Option<Id>,
        rename: &dyn Fn(&str) -> String,
        memo: &mut HashMap<Id, Id>,
    ) -> Id {
        if let Some(&r) = memo.get(&id) {
            return r;
        }
        let node = self.node(id).clone();
        let mut s = |a: Id, this: &mut Arena| this.subst_memo(a, map, rename, memo);
        let r = match node {
            Node::Const(_) => id,
            Node::Sym(sym) => return map(self, sym).unwrap_or(id),
            Node::Add(a, b) => {
                let (a, b) = (s(a, self), s(b, self));
                self.add(a, b)
            }
            Node::Sub(a, b) => {
                let (a, b) = (s(a, self), s(b, self));
                self.sub(a, b)
            }
            Node::Mul(a, b) => {
                let (a, b) = (s(a, self), s(b, self));
                self.mul(a, b)
            }
            Node::Div(a, b) => {
                let (a, b) = (s(a, self), s(b, self));
                self.div(a, b)
            }
            Node::Powf(a, b) => {
                let (a, b) = (s(a, self), s(b, self));
                self.powf(a, b)
            }
            Node::Neg(a) => {
                let a = s(a, self);
                self.neg(a)
            }
            Node::Powi(a, k) => {
                let a = s(a, self);
                self.powi(a, k)
            }
            Node::Func(f, a) => {
                let a = s(a, self);
                self.func(f, a)
            }
            Node::Named(n, a) => {
                let a = s(a, self);
                let name = rename(self.name(n));
                self.named(&name, a)
            }
        };
        memo.insert(id, r);
        r
    }
}
