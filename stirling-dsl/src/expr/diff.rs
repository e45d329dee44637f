//! Symbolic differentiation.
//!
//! `d/ds` of a node is built bottom-up with the folding constructors, memoised
//! per node, so a shared subexpression is differentiated once.

use std::collections::HashMap;

use super::arena::Arena;
use super::node::{Func, Id, Node, Sym};

impl Arena {
    /// The derivative of `id` with respect to the symbol `s`.
    pub fn diff(&mut self, id: Id, s: Sym) -> Id {
        let mut memo = HashMap::new();
        self.diff_memo(id, s, &mut memo)
    }

    fn diff_memo(&mut self, id: Id, s: Sym, memo: &mut HashMap<Id, Id>) -> Id {
        if let Some(&d) = memo.get(&id) {
            return d;
        }
        let d = self.diff_node(id, s, memo);
        memo.insert(id, d);
        d
    }

    fn diff_node(&mut self, id: Id, s: Sym, memo: &mut HashMap<Id, Id>) -> Id {
        match self.node(id).clone() {
            Node::Const(_) => self.num(0.0),
            Node::Sym(t) => self.num(if t == s { 1.0 } else { 0.0 }),
            Node::Named(_, a) => self.diff_memo(a, s, memo),
            Node::Add(a, b) => {
                let (da, db) = (self.diff_memo(a, s, memo), self.diff_memo(b, s, memo));
                self.add(da, db)
            }
            Node::Sub(a, b) => {
                let (da, db) = (self.diff_memo(a, s, memo), self.diff_memo(b, s, memo));
                self.sub(da, db)
            }
            Node::Neg(a) => {
                let da = self.diff_memo(a, s, memo);
                self.neg(da)
            }
            Node::Mul(a, b) => {
                let (da, db) = (self.diff_memo(a, s, memo), self.diff_memo(b, s, memo));
                let (l, r) = (self.mul(da, b), self.mul(a, db));
                self.add(l, r)
            }
            Node::Div(a, b) => self.diff_div(a, b, s, memo),
            Node::Powi(a, k) => {
                let da = self.diff_memo(a, s, memo);
                let p = self.powi(a, k - 1);
                let kk = self.num(k as f64);
                let kp = self.mul(kk, p);
                self.mul(kp, da)
            }
            Node::Powf(a, b) => self.diff_powf(id, a, b, s, memo),
            Node::Func(f, a) => {
                let da = self.diff_memo(a, s, memo);
                if self.as_const(da) == Some(0.0) {
                    return da;
                }
                let outer = self.func_derivative(f, id, a);
                self.mul(outer, da)
            }
        }
    }

    /// `(a/b)' = a'/b - a b'/b^2`, written as `(a' - (a/b) b')/b` to reuse `a/b`.
    fn diff_div(&mut self, a: Id, b: Id, s: Sym, memo: &mut HashMap<Id, Id>) -> Id {
        let (da, db) = (self.diff_memo(a, s, memo), self.diff_memo(b, s, memo));
        if self.as_const(db) == Some(0.0) {
            return self.div(da, b);
        }
        let q = self.div(a, b);
        let qdb = self.mul(q, db);
        let num = self.sub(da, qdb);
        self.div(num, b)
    }

    /// `(a^b)' = a^b (b' ln a + b a'/a)`.
    fn diff_powf(&mut self, id: Id, a: Id, b: Id, s: Sym, memo: &mut HashMap<Id, Id>) -> Id {
        let (da, db) = (self.diff_memo(a, s, memo), self.diff_memo(b, s, memo));
        let ln_a = self.func(Func::Ln, a);
        let t1 = self.mul(db, ln_a);
        let ba = self.mul(b, da);
        let t2 = self.div(ba, a);
        let inner = self.add(t1, t2);
        self.mul(id, inner)
    }

    /// `f'(a)`, reusing the node `fa = f(a)` where the derivative is a function of it.
    fn func_derivative(&mut self, f: Func, fa: Id, a: Id) -> Id {
        match f {
            Func::Sqrt => {
                let two = self.num(2.0);
                let d = self.mul(two, fa);
                let one = self.num(1.0);
                self.div(one, d)
            }
            Func::Ln => {
                let one = self.num(1.0);
                self.div(one, a)
            }
            Func::Exp => fa,
            Func::Tanh => {
                let one = self.num(1.0);
                let sq = self.powi(fa, 2);
                self.sub(one, sq)
            }
            Func::Abs => self.func(Func::Sign, a),
            Func::Sign => self.num(0.0),
            Func::Sin => self.func(Func::Cos, a),
            Func::Cos => {
                let s = self.func(Func::Sin, a);
                self.neg(s)
            }
        }
    }
}
