//! The hash-consed expression arena and its folding constructors.
//!
//! Structurally equal nodes are stored once, so a shared subexpression is one
//! node: common-subexpression elimination is a by-product of construction, and
//! the code emitter only has to name nodes with several parents.

use std::collections::HashMap;

use super::node::{Func, Id, Node, Sym};

/// A flat store of expression nodes, children before parents.
#[derive(Clone, Debug, Default)]
pub struct Arena {
    nodes: Vec<Node>,
    dedup: HashMap<Node, Id>,
    names: Vec<String>,
}

impl Arena {
    /// An empty arena.
    pub fn new() -> Self {
        Self::default()
    }

    /// The node behind an id.
    pub fn node(&self, id: Id) -> &Node {
        &self.nodes[id.index()]
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the arena holds no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The text of a name registered with [`Arena::named`].
    pub fn name(&self, index: u32) -> &str {
        &self.names[index as usize]
    }

    fn intern(&mut self, node: Node) -> Id {
        if let Some(&id) = self.dedup.get(&node) {
            return id;
        }
        let id = Id(self.nodes.len() as u32);
        self.nodes.push(node.clone());
        self.dedup.insert(node, id);
        id
    }

    /// The id of `node` if the arena holds it (no folding, nothing added).
    pub fn find(&self, node: &Node) -> Option<Id> {
        self.dedup.get(node).copied()
    }

    /// `node` through the folding constructors (a `Named` node is interned as it is).
    pub fn make(&mut self, node: Node) -> Id {
        match node {
            Node::Const(bits) => self.num(f64::from_bits(bits)),
            Node::Sym(s) => self.sym(s),
            Node::Add(a, b) => self.add(a, b),
            Node::Sub(a, b) => self.sub(a, b),
            Node::Mul(a, b) => self.mul(a, b),
            Node::Div(a, b) => self.div(a, b),
            Node::Neg(a) => self.neg(a),
            Node::Powi(a, k) => self.powi(a, k),
            Node::Powf(a, b) => self.powf(a, b),
            Node::Func(f, a) => self.func(f, a),
            Node::Named(..) => self.intern(node),
        }
    }

    /// A constant.
    pub fn num(&mut self, v: f64) -> Id {
        // one representation of zero, so that folding sees it
        let v = if v == 0.0 { 0.0 } else { v };
        self.intern(Node::Const(v.to_bits()))
    }

    /// A symbol.
    pub fn sym(&mut self, s: Sym) -> Id {
        self.intern(Node::Sym(s))
    }

    /// The constant value of a node, if it is one.
    pub fn as_const(&self, id: Id) -> Option<f64> {
        match self.node(id) {
            Node::Const(bits) => Some(f64::from_bits(*bits)),
            _ => None,
        }
    }

    /// `a + b`, folding constants and zeros.
    pub fn add(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.num(x + y),
            (Some(x), _) if x == 0.0 => b,
            (_, Some(y)) if y == 0.0 => a,
            _ => match *self.node(b) {
                Node::Neg(nb) => self.sub(a, nb),
                _ => self.intern(Node::Add(a, b)),
            },
        }
    }

    /// `a - b`, folding constants and zeros.
    pub fn sub(&mut self, a: Id, b: Id) -> Id {
        if a == b {
            return self.num(0.0);
        }
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => self.num(x - y),
            (Some(x), _) if x == 0.0 => self.neg(b),
            (_, Some(y)) if y == 0.0 => a,
            _ => match *self.node(b) {
                Node::Neg(nb) => self.add(a, nb),
                _ => self.intern(Node::Sub(a, b)),
            },
        }
    }

    /// `-a`.
    pub fn neg(&mut self, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.num(-x);
        }
        match *self.node(a) {
            Node::Neg(inner) => inner,
            Node::Sub(x, y) => self.sub(y, x),
            _ => self.intern(Node::Neg(a)),
        }
    }

    /// `a * b`, folding constants, zeros, ones and signs.
    pub fn mul(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) => return self.num(x * y),
            (Some(x), _) if x == 0.0 => return a,
            (_, Some(y)) if y == 0.0 => return b,
            (Some(x), _) if x == 1.0 => return b,
            (_, Some(y)) if y == 1.0 => return a,
            (Some(x), _) if x == -1.0 => return self.neg(b),
            (_, Some(y)) if y == -1.0 => return self.neg(a),
            _ => {}
        }
        match (self.node(a).clone(), self.node(b).clone()) {
            (Node::Neg(x), Node::Neg(y)) => self.mul(x, y),
            (Node::Neg(x), _) => {
                let m = self.mul(x, b);
                self.neg(m)
            }
            (_, Node::Neg(y)) => {
                let m = self.mul(a, y);
                self.neg(m)
            }
            // constants to the left, so that printing reads `2 * x`
            _ if self.as_const(b).is_some() => self.intern(Node::Mul(b, a)),
            _ => self.intern(Node::Mul(a, b)),
        }
    }

    /// `a / b`, folding constants, ones and zeros (never folds a division by zero).
    pub fn div(&mut self, a: Id, b: Id) -> Id {
        match (self.as_const(a), self.as_const(b)) {
            (Some(x), Some(y)) if y != 0.0 => return self.num(x / y),
            (Some(x), _) if x == 0.0 => return a,
            (_, Some(y)) if y == 1.0 => return a,
            (_, Some(y)) if y == -1.0 => return self.neg(a),
            _ => {}
        }
        if a == b {
            return self.num(1.0);
        }
        match (self.node(a).clone(), self.node(b).clone()) {
            (Node::Neg(x), _) => {
                let d = self.div(x, b);
                self.neg(d)
            }
            (_, Node::Neg(y)) => {
                let d = self.div(a, y);
                self.neg(d)
            }
            _ => self.intern(Node::Div(a, b)),
        }
    }

    /// `a ^ k` for an integer `k`.
    pub fn powi(&mut self, a: Id, k: i32) -> Id {
        match k {
            0 => return self.num(1.0),
            1 => return a,
            _ => {}
        }
        if let Some(x) = self.as_const(a) {
            return self.num(x.powi(k));
        }
        if k == -1 {
            let one = self.num(1.0);
            return self.div(one, a);
        }
        self.intern(Node::Powi(a, k))
    }

    /// `a ^ b` for a real exponent.
    pub fn powf(&mut self, a: Id, b: Id) -> Id {
        if let Some(e) = self.as_const(b) {
            if e.fract() == 0.0 && e.abs() < 64.0 {
                return self.powi(a, e as i32);
            }
            if let Some(x) = self.as_const(a) {
                return self.num(x.powf(e));
            }
        }
        self.intern(Node::Powf(a, b))
    }

    /// `f(a)`.
    pub fn func(&mut self, f: Func, a: Id) -> Id {
        if let Some(x) = self.as_const(a) {
            return self.num(f.apply(x));
        }
        self.intern(Node::Func(f, a))
    }

    /// Give `value` a name for printing; transparent otherwise. Constants and bare
    /// symbols are not named (the name would only hide them).
    pub fn named(&mut self, name: &str, value: Id) -> Id {
        if matches!(self.node(value), Node::Const(_) | Node::Sym(_)) {
            return value;
        }
        let index = match self.names.iter().position(|n| n == name) {
            Some(i) => i as u32,
            None => {
                self.names.push(name.to_string());
                (self.names.len() - 1) as u32
            }
        };
        self.intern(Node::Named(index, value))
    }

    /// Strip any `Named` wrappers.
    pub fn unname(&self, mut id: Id) -> Id {
        while let Node::Named(_, inner) = *self.node(id) {
            id = inner;
        }
        id
    }

    /// Sum of many terms.
    pub fn sum(&mut self, terms: impl IntoIterator<Item = Id>) -> Id {
        let zero = self.num(0.0);
        terms.into_iter().fold(zero, |acc, t| self.add(acc, t))
    }

    /// Whether the symbol occurs below `id`.
    pub fn depends_on(&self, id: Id, s: Sym) -> bool {
        self.symbols(id).contains(&s)
    }

    /// All symbols below `id`, sorted.
    pub fn symbols(&self, id: Id) -> Vec<Sym> {
        let mut seen = vec![false; self.nodes.len()];
        let mut out = Vec::new();
        let mut stack = vec![id];
        while let Some(i) = stack.pop() {
            if std::mem::replace(&mut seen[i.index()], true) {
                continue;
            }
            match self.node(i) {
                Node::Sym(s) => out.push(*s),
                n => stack.extend(n.children()),
            }
        }
        out.sort();
        out.dedup();
        out
    }
}
