//! Parameters folded into a tape: every `Op::P(k)` becomes the number `p[k]`, every
//! instruction whose operands are all numbers becomes its value (computed with the
//! interpreter's own arithmetic, so a folded tape gives bit for bit what the tape gives at
//! `p`), and the instructions no output reaches any more are dropped.

use super::tape::{prune, Op, Tape};

/// The value of `op` if its operands are numbers (`known[k]`: register `k`'s number).
fn constant(op: &Op, p: &[f64], known: &[Option<f64>]) -> Option<f64> {
    let g = |k: u32| known[k as usize];
    Some(match *op {
        Op::X(_) | Op::V(_) => return None,
        Op::P(k) => *p.get(k as usize)?,
        Op::K(c) => c,
        Op::Add(a, b) => g(a)? + g(b)?,
        Op::Sub(a, b) => g(a)? - g(b)?,
        Op::Mul(a, b) => g(a)? * g(b)?,
        Op::Div(a, b) => g(a)? / g(b)?,
        Op::Neg(a) => -g(a)?,
        Op::Powi(a, k) => g(a)?.powi(k),
        Op::Powf(a, b) => g(a)?.powf(g(b)?),
        Op::Func(f, a) => f.apply(g(a)?),
        Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => {
            super::tape::fused_value(op, g(a)?, g(b)?, g(c)?)?
        }
    })
}

impl Tape {
    /// This tape with the parameters `p` folded in (a parameter index outside `p` stays an
    /// input).
    pub fn fold(&self, p: &[f64]) -> Tape {
        self.fold_with(p, false)
    }

    /// [`Tape::fold`] with the rewrites of `peephole.rs` (constants reassociated, negations
    /// absorbed, divisions by a number made products) and every sum of a product nothing
    /// else reads fused into one multiply-add (`fuse_mul_add`).
    pub fn fold_fused(&self, p: &[f64]) -> Tape {
        self.fold_with(p, true)
    }

    fn fold_with(&self, p: &[f64], fuse: bool) -> Tape {
        let mut known = Vec::with_capacity(self.ops.len());
        let folded: Vec<Op> = self
            .ops
            .iter()
            .map(|op| {
                let c = constant(op, p, &known);
                known.push(c);
                c.map_or(*op, Op::K)
            })
            .collect();
        let (ops, outputs, sections) = if fuse {
            let (mut f, outputs, sections) =
                super::peephole::simplify(folded, &self.outputs, &self.sections);
            fuse_mul_add(&mut f, &outputs);
            prune(f, &outputs, &sections)
        } else {
            prune(folded, &self.outputs, &self.sections)
        };
        Tape {
            ops,
            outputs,
            split: self.split,
            sections,
        }
    }
}

/// Every sum of a product that nothing else reads becomes one fused multiply-add (`a * b +
/// c` rounded once, [`Op::MulAdd`]); the product is then read by nothing and pruned. What a
/// C compiler does under `-ffp-contract=fast` (GCC's default, and what CasADi's literal C
/// gets): one instruction for two, and the sum's rounding of the product gone, which moves
/// a result by at most an ulp of the product per fused sum, and an entry that cancels much
/// larger terms by more of itself (a Jacobian entry of 3.19e4 in a row reaching 7.6e12 moved
/// by 2e-9 of itself). Only on the folded right-hand side and Jacobian (the simulation's
/// work): a tape with the parameters as inputs, and the other folded functions (the
/// parameter Jacobian, where entries of 4.8e11 moved by 1e-11 of themselves at n = 100),
/// keep the macro's operations one for one.
fn fuse_mul_add(ops: &mut [Op], outputs: &[u32]) {
    let mut uses = vec![0u32; ops.len()];
    for op in ops.iter() {
        let (args, count) = super::tape::operands(op);
        for &a in &args[..count] {
            uses[a as usize] += 1;
        }
    }
    for &o in outputs {
        uses[o as usize] += 1;
    }
    for k in 0..ops.len() {
        let product = |r: u32| match ops[r as usize] {
            Op::Mul(a, b) if uses[r as usize] == 1 => Some((a, b)),
            _ => None,
        };
        let fused = match ops[k] {
            Op::Add(x, y) => match (product(x), product(y)) {
                (Some((a, b)), _) => Some(Op::MulAdd(a, b, y)),
                (None, Some((a, b))) => Some(Op::MulAdd(a, b, x)),
                _ => None,
            },
            Op::Sub(x, y) => match (product(x), product(y)) {
                (Some((a, b)), _) => Some(Op::MulSub(a, b, y)),
                (None, Some((a, b))) => Some(Op::NegMulAdd(a, b, x)),
                _ => None,
            },
            _ => None,
        };
        if let Some(f) = fused {
            ops[k] = f;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(p0 * x0 + p1) / p0`: folded, two of its instructions are numbers.
    #[test]
    fn folds_parameters_and_what_they_reach() {
        let t = Tape {
            ops: vec![
                Op::P(0),
                Op::X(0),
                Op::Mul(0, 1),
                Op::P(1),
                Op::Add(2, 3),
                Op::Add(0, 3),
                Op::Div(4, 5),
            ],
            outputs: vec![6, 5],
            split: None,
            sections: Vec::new(),
        };
        let p = [2.0, 3.0];
        let f = t.fold(&p);
        assert!(f.ops.iter().all(|o| !matches!(o, Op::P(_))), "{:?}", f.ops);
        // `p0 + p1` became a number: one arithmetic instruction fewer
        let arithmetic = |t: &Tape| {
            t.ops
                .iter()
                .filter(|o| !matches!(o, Op::P(_) | Op::X(_) | Op::K(_) | Op::V(_)))
                .count()
        };
        assert_eq!(arithmetic(&f), arithmetic(&t) - 1, "{:?}", f.ops);
        assert!(f.ops.contains(&Op::K(5.0)), "{:?}", f.ops);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for x in [0.5, -7.0, 1e9] {
            t.run(&p, &[x], &[], &mut a);
            f.run(&[], &[x], &[], &mut b);
            for k in 0..2 {
                assert_eq!(t.output(&a, k).to_bits(), f.output(&b, k).to_bits());
            }
        }
    }

    /// `x0 * x1 + x2`, `x0 * x2 - x1`, `x2 - x1 * x0` and a product read twice: the three
    /// sums of a product read once fuse (and the products go), the fourth stays; the fused
    /// values are `mul_add`'s, not the two roundings'.
    #[test]
    fn sums_of_products_read_once_fuse() {
        let t = Tape {
            ops: vec![
                Op::X(0),
                Op::X(1),
                Op::X(2),
                Op::Mul(0, 1),
                Op::Add(3, 2),
                Op::Mul(0, 2),
                Op::Sub(5, 1),
                Op::Mul(1, 0),
                Op::Sub(2, 7),
                Op::Mul(1, 2),
                Op::Add(9, 9),
            ],
            outputs: vec![4, 6, 8, 10],
            split: None,
            sections: Vec::new(),
        };
        let f = t.fold_fused(&[]);
        let count = |pred: fn(&Op) -> bool| f.ops.iter().filter(|o| pred(o)).count();
        assert_eq!(count(|o| matches!(o, Op::MulAdd(..))), 1, "{:?}", f.ops);
        assert_eq!(count(|o| matches!(o, Op::MulSub(..))), 1, "{:?}", f.ops);
        assert_eq!(count(|o| matches!(o, Op::NegMulAdd(..))), 1, "{:?}", f.ops);
        assert_eq!(count(|o| matches!(o, Op::Mul(..))), 1, "{:?}", f.ops);
        let x = [0.1, 3.0, 1.0 / 3.0];
        let (mut a, mut b) = (Vec::new(), Vec::new());
        f.run(&[], &x, &[], &mut a);
        t.run(&[], &x, &[], &mut b);
        let out = |t: &Tape, r: &[f64], k: usize| r[t.outputs[k] as usize];
        assert_eq!(out(&f, &a, 0), x[0].mul_add(x[1], x[2]));
        assert_eq!(out(&f, &a, 1), x[0].mul_add(x[2], -x[1]));
        assert_eq!(out(&f, &a, 2), (-x[1]).mul_add(x[0], x[2]));
        assert_eq!(out(&f, &a, 3), out(&t, &b, 3));
        // unfused, `fold` keeps the operations one for one
        assert_eq!(t.fold(&[]).ops, t.ops);
    }
}
