//! Value numbering for one generated function: the model's expressions imported into a
//! fresh arena without their `Named` wrappers (a quantity named in one frame and under
//! another name in the next section's frame is one value), specialised to the first, last
//! and only section (the section's own element becomes `First`/`Last`, so that a link to a
//! scalar end is one value in the scalar row and in the section row), and shifted by one
//! section (the inflow of section `j` is the outflow of section `j - 1`).

use std::collections::HashMap;

use crate::expr::{Arena, At, Id, Node, Sym};

/// `a / b` as the generated code computes it: `a * (1 / b)` unless `b` is a number; a
/// number over `b` stays one division, `-c / b` as `-(c / b)` (the same value: one division
/// for `1 / b` and `-1 / b`).
///
/// A divisor fixed for the call (`Rf / n`, `eps`, a section's volume) then has its
/// reciprocal hoisted out of the section loop and shared by every use, so the loop
/// multiplies where it divided. The rule does not look at what `b` depends on, so an
/// effect's divisor `b + c x` gives the same bits as the base model's `b` at its null
/// `c = 0` (`1 / b` is the same division in both): the augmented model at its null stays
/// the base model bit for bit (tests/effects_nominal.rs).
pub fn quotient(arena: &mut Arena, a: Id, b: Id) -> Id {
    match (arena.as_const(a), arena.as_const(b)) {
        (_, Some(_)) => return arena.div(a, b),
        (Some(c), None) if c < 0.0 => {
            let c = arena.num(-c);
            let q = arena.div(c, b);
            return arena.neg(q);
        }
        (Some(_), None) => return arena.div(a, b),
        (None, None) => {}
    }
    let one = arena.num(1.0);
    let r = arena.div(one, b);
    arena.mul(a, r)
}

/// A copy of `roots` (with their names) in which every division is a [`quotient`], for the
/// code emitted without value numbering (the sums over the sections): the same bits as the
/// rows that read the same links.
pub fn reciprocal_form(src: &Arena, roots: &[Id]) -> (Arena, Vec<Id>) {
    fn go(src: &Arena, id: Id, dst: &mut Arena, memo: &mut HashMap<Id, Id>) -> Id {
        if let Some(&r) = memo.get(&id) {
            return r;
        }
        let node = src.node(id).clone();
        let kids: Vec<Id> = node
            .children()
            .iter()
            .map(|&c| go(src, c, dst, memo))
            .collect();
        let r = match node {
            Node::Named(n, _) => dst.named(src.name(n), kids[0]),
            Node::Div(..) => quotient(dst, kids[0], kids[1]),
            _ => dst.make(node.with_children(&kids)),
        };
        memo.insert(id, r);
        r
    }
    let (mut dst, mut memo) = (Arena::new(), HashMap::new());
    let ids = roots
        .iter()
        .map(|&r| go(src, r, &mut dst, &mut memo))
        .collect();
    (dst, ids)
}

/// Which section a block of the section loop is specialised to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Section {
    /// `j = 0` of `n >= 2`.
    First,
    /// `j = n - 1` of `n >= 2`.
    Last,
    /// `j = 0` of `n = 1`.
    Single,
}

/// What a node depends on, for hoisting and carrying.
#[derive(Clone, Copy, Debug, Default)]
pub struct Reach {
    /// Reads the section index `j`.
    pub index: bool,
    /// Smallest and largest relative offset of the state elements read (`None`: none).
    pub rel: Option<(i32, i32)>,
}

impl Reach {
    /// Whether the node changes with the section of the loop.
    pub fn varies(&self) -> bool {
        self.index || self.rel.is_some()
    }

    fn join(self, o: Reach) -> Reach {
        let rel = match (self.rel, o.rel) {
            (Some((a, b)), Some((c, d))) => Some((a.min(c), b.max(d))),
            (a, b) => a.or(b),
        };
        Reach {
            index: self.index || o.index,
            rel,
        }
    }
}

/// The value-numbered arena with the preferred name of every value.
#[derive(Default)]
pub struct Canon {
    pub arena: Arena,
    names: Vec<Option<String>>,
    memo: HashMap<Id, Id>,
    at_memo: HashMap<(Id, Section), Id>,
}

impl Canon {
    /// `id` of `src`, unnamed; its name (the first one met) is kept aside.
    pub fn import(&mut self, src: &Arena, id: Id) -> Id {
        if let Some(&r) = self.memo.get(&id) {
            return r;
        }
        let node = src.node(id).clone();
        let r = if let Node::Named(n, a) = node {
            let r = self.import(src, a);
            self.set_name(r, src.name(n));
            r
        } else {
            let kids: Vec<Id> = node
                .children()
                .iter()
                .map(|&c| self.import(src, c))
                .collect();
            match node {
                Node::Div(..) => quotient(&mut self.arena, kids[0], kids[1]),
                _ => self.arena.make(node.with_children(&kids)),
            }
        };
        self.memo.insert(id, r);
        r
    }

    fn set_name(&mut self, id: Id, name: &str) {
        if self.names.len() <= id.index() {
            self.names.resize(id.index() + 1, None);
        }
        if self.names[id.index()].is_none() {
            self.names[id.index()] = Some(name.to_string());
        }
    }

    /// The preferred name of every node (`None`: a temporary).
    pub fn names(&self) -> Vec<Option<String>> {
        let mut out = self.names.clone();
        out.resize(self.arena.len(), None);
        out
    }

    /// The name of `id`, if it has one.
    pub fn name(&self, id: Id) -> Option<&str> {
        self.names.get(id.index()).and_then(|n| n.as_deref())
    }

    /// `id` (a section-frame value) at the section `sec`: its own element `Rel(0)` becomes
    /// `First`/`Last`, the index `j` a number.
    pub fn at(&mut self, id: Id, sec: Section) -> Id {
        if let Some(&r) = self.at_memo.get(&(id, sec)) {
            return r;
        }
        let node = self.arena.node(id).clone();
        let r = match node {
            Node::Sym(s) => self.at_sym(s, sec),
            _ => {
                let kids: Vec<Id> = node.children().iter().map(|&c| self.at(c, sec)).collect();
                self.arena.make(node.with_children(&kids))
            }
        };
        if let Some(n) = self.name(id).map(str::to_string) {
            self.set_name(r, &n);
        }
        self.at_memo.insert((id, sec), r);
        r
    }

    fn at_sym(&mut self, s: Sym, sec: Section) -> Id {
        let own = match sec {
            Section::First | Section::Single => At::First,
            Section::Last => At::Last,
        };
        match s {
            Sym::State(b, At::Rel(0)) => self.arena.sym(Sym::State(b, own)),
            Sym::State(b, At::Last) if sec == Section::Single => {
                self.arena.sym(Sym::State(b, At::First))
            }
            Sym::Index if sec == Section::Last => {
                let (n, one) = (self.arena.sym(Sym::Count), self.arena.num(1.0));
                self.arena.sub(n, one)
            }
            Sym::Index => self.arena.num(0.0),
            _ => self.arena.sym(s),
        }
    }

    /// The node that is `id` moved `d` sections on (`Rel(k)` read as `Rel(k + d)`), if the
    /// arena holds it; `None` for anything that reads the index `j`.
    pub fn shifted(&self, id: Id, d: i32, memo: &mut HashMap<Id, Option<Id>>) -> Option<Id> {
        if let Some(&r) = memo.get(&id) {
            return r;
        }
        let node = self.arena.node(id);
        let r = match *node {
            Node::Const(_) => Some(id),
            Node::Sym(Sym::State(b, At::Rel(k))) => {
                self.arena.find(&Node::Sym(Sym::State(b, At::Rel(k + d))))
            }
            Node::Sym(Sym::Index) => None,
            Node::Sym(_) => Some(id),
            _ => {
                let mut kids = Vec::new();
                for c in node.children() {
                    kids.push(self.shifted(c, d, memo)?);
                }
                self.arena.find(&node.with_children(&kids))
            }
        };
        memo.insert(id, r);
        r
    }

    /// What every node depends on (children come before parents).
    pub fn reach(&self) -> Vec<Reach> {
        let mut out: Vec<Reach> = vec![Reach::default(); self.arena.len()];
        for i in 0..self.arena.len() {
            out[i] = match *self.arena.node(Id(i as u32)) {
                Node::Const(_) => Reach::default(),
                Node::Sym(Sym::Index) => Reach {
                    index: true,
                    rel: None,
                },
                Node::Sym(Sym::State(_, At::Rel(k))) => Reach {
                    index: false,
                    rel: Some((k, k)),
                },
                Node::Sym(_) => Reach::default(),
                ref n => n
                    .children()
                    .iter()
                    .fold(Reach::default(), |acc, c| acc.join(out[c.index()])),
            };
        }
        out
    }
}
