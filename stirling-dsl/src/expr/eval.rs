//! Numeric evaluation of expressions (tests, constant defaults, checks).

use super::arena::Arena;
use super::node::{Id, Node, Sym};

impl Arena {
    /// Nodes reachable from `roots`, as a mask over the arena.
    pub fn reachable(&self, roots: &[Id]) -> Vec<bool> {
        let mut seen = vec![false; self.len()];
        let mut stack = roots.to_vec();
        while let Some(i) = stack.pop() {
            if !std::mem::replace(&mut seen[i.index()], true) {
                stack.extend(self.node(i).children());
            }
        }
        seen
    }

    /// Evaluate `id`, asking `value` for each symbol. Children precede parents in
    /// the arena, so one pass in index order over the reachable nodes suffices.
    pub fn eval(&self, id: Id, value: &mut dyn FnMut(Sym) -> f64) -> f64 {
        let mask = self.reachable(&[id]);
        let mut v = vec![0.0; id.index() + 1];
        for i in 0..=id.index() {
            if mask[i] {
                v[i] = self.eval_node(self.node(Id(i as u32)), &v, value);
            }
        }
        v[id.index()]
    }

    fn eval_node(&self, node: &Node, v: &[f64], value: &mut dyn FnMut(Sym) -> f64) -> f64 {
        let g = |c: Id| v[c.index()];
        match *node {
            Node::Const(bits) => f64::from_bits(bits),
            Node::Sym(s) => value(s),
            Node::Add(a, b) => g(a) + g(b),
            Node::Sub(a, b) => g(a) - g(b),
            Node::Mul(a, b) => g(a) * g(b),
            Node::Div(a, b) => g(a) / g(b),
            Node::Neg(a) => -g(a),
            Node::Powi(a, k) => g(a).powi(k),
            Node::Powf(a, b) => g(a).powf(g(b)),
            Node::Func(f, a) => f.apply(g(a)),
            Node::Named(_, a) => g(a),
        }
    }

    /// Evaluate an expression that holds no symbol (constant defaults).
    pub fn eval_const(&self, id: Id) -> Option<f64> {
        if !self.symbols(id).is_empty() {
            return None;
        }
        Some(self.eval(id, &mut |_| f64::NAN))
    }
}
