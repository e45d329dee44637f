//! Rewrites of a folded tape that a C compiler may not make without `-ffast-math`, each one
//! instruction for one (so a tape's layout, its sections included, is kept) and each freeing
//! the instruction it reads when nothing else reads it (then pruned):
//!
//! - `(y * k1) * k2` becomes `y * (k1 k2)`, and `k1 / (y * k2)` becomes `(k1 / k2) / y`
//!   (reassociated: the folded constants' one rounding instead of two);
//! - `-(y * k)` and `(-y) * k` become `y * (-k)`; `a + (-y)` becomes `a - y` and `a - (-y)`
//!   becomes `a + y` (exact);
//! - `a / k` becomes `a * (1 / k)` (a multiplication for a division; the reciprocal's
//!   rounding).
//!
//! A reassociated or reciprocal number is made only when it is a normal number (neither
//! zero, subnormal nor infinite): `(y * 1e-200) * 1e-200` must not become `y * 0`.
//!
//! Only on the folded right-hand side and Jacobian, with the multiply-adds
//! ([`super::Tape::fold_fused`]): the simulation's work, whose results already differ from
//! the macro's by ulps. A new number goes just before the instruction that reads it (inside
//! its section; a number shared with other readers is never changed).

use super::tape::{operands, renumber, Op};

/// `ops` (outputs `outputs`, section marks `marks`) rewritten by the rules of the module
/// doc, with the outputs and marks moved to where their instructions went.
pub(crate) fn simplify(
    ops: Vec<Op>,
    outputs: &[u32],
    marks: &[u32],
) -> (Vec<Op>, Vec<u32>, Vec<u32>) {
    let n = ops.len();
    let mut uses = vec![0u32; ops.len()];
    for op in ops.iter() {
        let (args, count) = operands(op);
        for &a in &args[..count] {
            uses[a as usize] += 1;
        }
    }
    for &o in outputs {
        uses[o as usize] += 1;
    }
    let mut r = Rewriter {
        ops,
        uses,
        inserted: Vec::new(),
    };
    for k in 0..n {
        r.visit(k);
    }
    r.layout(n, outputs, marks)
}

struct Rewriter {
    /// The tape's instructions, then the new numbers.
    ops: Vec<Op>,
    uses: Vec<u32>,
    /// Each new number's register and the instruction it goes before.
    inserted: Vec<(u32, usize)>,
}

impl Rewriter {
    /// The number at register `r`.
    fn number(&self, r: u32) -> Option<f64> {
        match self.ops[r as usize] {
            Op::K(c) => Some(c),
            _ => None,
        }
    }

    /// A new number `c`, placed before instruction `k`, when it is normal (see the module
    /// doc; the exact rules' negated numbers always are when their source is).
    fn normal(&mut self, c: f64, k: usize) -> Option<u32> {
        c.is_normal().then(|| self.konst(c, k))
    }

    /// A new number `c`, placed before instruction `k`.
    fn konst(&mut self, c: f64, k: usize) -> u32 {
        let r = self.ops.len() as u32;
        self.ops.push(Op::K(c));
        self.uses.push(0);
        self.inserted.push((r, k));
        r
    }

    /// The first `n` instructions with the new numbers in their places, renumbered; the
    /// outputs and marks moved with them.
    fn layout(self, n: usize, outputs: &[u32], marks: &[u32]) -> (Vec<Op>, Vec<u32>, Vec<u32>) {
        let mut before: Vec<Vec<u32>> = vec![Vec::new(); n];
        for &(r, k) in &self.inserted {
            before[k].push(r);
        }
        let mut to = vec![u32::MAX; self.ops.len()];
        let mut first = Vec::with_capacity(n + 1);
        let mut out = Vec::with_capacity(self.ops.len());
        for (k, news) in before.iter().enumerate() {
            first.push(out.len() as u32);
            for &r in news {
                to[r as usize] = out.len() as u32;
                out.push(self.ops[r as usize]);
            }
            to[k] = out.len() as u32;
            out.push(renumber(self.ops[k], &to));
        }
        first.push(out.len() as u32);
        let outputs = outputs.iter().map(|&o| to[o as usize]).collect();
        let marks = marks.iter().map(|&m| first[(m as usize).min(n)]).collect();
        (out, outputs, marks)
    }

    /// `y * k` at `r` (either order) with `k` a number, if nothing but one instruction
    /// reads `r`: `(y, k)`.
    fn scaled(&self, r: u32) -> Option<(u32, f64)> {
        if self.uses[r as usize] != 1 {
            return None;
        }
        let Op::Mul(a, b) = self.ops[r as usize] else {
            return None;
        };
        self.number(b)
            .map(|c| (a, c))
            .or_else(|| self.number(a).map(|c| (b, c)))
    }

    /// `-y` at `r`, if nothing but one instruction reads `r`.
    fn negated(&self, r: u32) -> Option<u32> {
        match self.ops[r as usize] {
            Op::Neg(y) if self.uses[r as usize] == 1 => Some(y),
            _ => None,
        }
    }

    /// One reader fewer of `r`; an instruction nobody reads frees its operands.
    fn release(&mut self, r: u32) {
        let u = &mut self.uses[r as usize];
        *u -= 1;
        if *u == 0 {
            let (args, count) = operands(&self.ops[r as usize]);
            for &a in &args[..count] {
                self.release(a);
            }
        }
    }

    /// Replace instruction `k` (whose operands were `old`) by `op` (operands `new`).
    fn replace(&mut self, k: usize, op: Op) {
        let (old, n_old) = operands(&self.ops[k]);
        let (new, n_new) = operands(&op);
        for &a in &new[..n_new] {
            self.uses[a as usize] += 1;
        }
        self.ops[k] = op;
        for &a in &old[..n_old] {
            self.release(a);
        }
    }

    fn visit(&mut self, k: usize) {
        if self.uses[k] == 0 {
            return;
        }
        match self.ops[k] {
            Op::Mul(a, b) => self.product(k, a, b),
            Op::Neg(a) => {
                if let Some((y, c)) = self.scaled(a) {
                    let kr = self.konst(-c, k);
                    self.replace(k, Op::Mul(y, kr));
                }
            }
            Op::Add(a, b) => {
                if let Some(y) = self.negated(b) {
                    self.replace(k, Op::Sub(a, y));
                } else if let Some(y) = self.negated(a) {
                    self.replace(k, Op::Sub(b, y));
                }
            }
            Op::Sub(a, b) => {
                if let Some(y) = self.negated(b) {
                    self.replace(k, Op::Add(a, y));
                }
            }
            Op::Div(a, b) => {
                if let Some(c) = self.number(b).filter(|c| c.is_normal()) {
                    if let Some(kr) = self.normal(1.0 / c, k) {
                        self.replace(k, Op::Mul(a, kr));
                    }
                } else if let (Some(c1), Some((y, c2))) = (self.number(a), self.scaled(b)) {
                    if let Some(kr) = self.normal(c1 / c2, k) {
                        self.replace(k, Op::Div(kr, y));
                    }
                }
            }
            _ => {}
        }
    }

    /// `a * b` at `k`: a number times `y * k1` or `-y` folds into one product.
    fn product(&mut self, k: usize, a: u32, b: u32) {
        let (x, c) = match (self.number(b), self.number(a)) {
            (Some(c), _) => (a, c),
            (None, Some(c)) => (b, c),
            _ => return,
        };
        if let Some((y, c1)) = self.scaled(x) {
            if let Some(kr) = self.normal(c1 * c, k) {
                self.replace(k, Op::Mul(y, kr));
            }
        } else if let Some(y) = self.negated(x) {
            let kr = self.konst(-c, k);
            self.replace(k, Op::Mul(y, kr));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tape::{prune, Tape};
    use super::*;

    fn run(ops: Vec<Op>, outputs: Vec<u32>, x: &[f64]) -> (Vec<f64>, usize) {
        let t = Tape {
            ops,
            outputs,
            split: None,
            sections: Vec::new(),
        };
        let mut regs = Vec::new();
        t.run(&[], x, &[], &mut regs);
        let vals = (0..t.outputs.len()).map(|k| t.output(&regs, k)).collect();
        (vals, t.ops.len())
    }

    fn simplified(ops: &[Op], outputs: &[u32]) -> (Vec<Op>, Vec<u32>) {
        let (o, out, _) = simplify(ops.to_vec(), outputs, &[]);
        let (o, out, _) = prune(o, &out, &[]);
        (o, out)
    }

    /// Every rule once: each result within two ulps of the tape as written, with fewer
    /// instructions; a number two instructions read stays for both.
    #[test]
    fn the_rewrites_keep_the_values_and_drop_instructions() {
        use Op::*;
        let ops = vec![
            X(0),        // 0
            K(3.0),      // 1
            Mul(0, 1),   // 2: x * 3
            K(0.7),      // 3
            Mul(2, 3),   // 4: (x * 3) * 0.7
            X(1),        // 5
            Neg(5),      // 6: -y
            Add(0, 6),   // 7: x + (-y)
            K(1.9),      // 8
            Mul(0, 8),   // 9
            Neg(9),      // 10: -(x * 1.9)
            K(7.0),      // 11
            Div(0, 11),  // 12: x / 7
            K(2.5),      // 13
            K(0.3),      // 14
            Mul(5, 14),  // 15
            Div(13, 15), // 16: 2.5 / (y * 0.3)
            K(5.0),      // 17: read twice
            Mul(0, 17),  // 18
            Mul(5, 17),  // 19
            Neg(0),      // 20
            Sub(5, 20),  // 21: y - (-x)
        ];
        let outputs = vec![4, 7, 10, 12, 16, 18, 19, 21];
        let x = [1.234_567, -0.987_654_3];
        let (want, n0) = run(ops.clone(), outputs.clone(), &x);
        let (o, out) = simplified(&ops, &outputs);
        assert!(
            !o.iter().any(|op| matches!(op, Div(_, 11) | Neg(_))),
            "{o:?}"
        );
        let (got, n1) = run(o.clone(), out, &x);
        assert!(n1 < n0 - 4, "{n0} -> {n1}: {o:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 4.0 * f64::EPSILON * w.abs(), "{g} vs {w}");
        }
        // `x * 5` and `y * 5` still read one shared 5
        assert_eq!(o.iter().filter(|op| **op == K(5.0)).count(), 1, "{o:?}");
    }

    /// A reassociated number that would underflow, or the reciprocal of a subnormal, is not
    /// made: the tape keeps its two roundings.
    #[test]
    fn numbers_out_of_the_normal_range_are_not_made() {
        use Op::*;
        let ops = vec![
            X(0),
            K(1e-200),
            Mul(0, 1),
            K(1e-200),
            Mul(2, 3), // (x * 1e-200) * 1e-200: 1e-400 underflows
            K(1e-310),
            Div(0, 5), // x / 1e-310: 1 / 1e-310 overflows
        ];
        let outputs = vec![4, 6];
        let (o, _) = simplified(&ops, &outputs);
        assert_eq!(o, ops, "{o:?}");
        let (got, _) = run(o, outputs, &[1e300]);
        assert_eq!(got, [1e300 * 1e-200 * 1e-200, 1e300 / 1e-310]);
    }
}
