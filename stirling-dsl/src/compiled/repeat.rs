//! The sections of a tape that repeat: in a function of the rows laid out section by
//! section ([`Tape::sections`]), the interior sections compute the same instructions, each
//! on its own section's states, with its own outputs, reading the values the previous
//! section carried over (the link between them) and the values computed once before them.
//! [`Tape::repeat`] finds such a run of sections and describes one of them as the body of a
//! loop ([`Repeat`]), so that native code can run one body per section instead of every
//! section unrolled (the macro's expansion loops over its interior sections likewise).
//!
//! Found, not assumed: the run is checked instruction by instruction in every section, so
//! any topology with arrays gets a loop where its sections repeat, and none where they do
//! not (the tape is then compiled unrolled).

use super::tape::{operands, Op, Tape};

/// A leaf read in iteration `i` of the loop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoopLeaf {
    /// State element `x[base + i * step]`.
    X { base: u32, step: i64 },
    /// Parameter `p[base + i * step]`.
    P { base: u32, step: i64 },
    /// A sensor's read value `v[base + i * step]`.
    V { base: u32, step: i64 },
    /// The same number in every iteration.
    K(f64),
    /// A number of each iteration's own: `Repeat::table[i * Repeat::cols + column]`
    /// (the section's index, e.g.).
    Table(u32),
}

/// An operand of a body instruction in iteration `i`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Arg {
    /// A leaf, read where it is used.
    Leaf(LoopLeaf),
    /// A register computed before the loop (the same in every iteration).
    Before(u32),
    /// Body instruction `t` of this iteration.
    Body(u32),
    /// Body instruction `t` of the previous iteration; in the first, register `init`
    /// (computed before the loop).
    Prev { t: u32, init: u32 },
}

/// One body instruction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// A leaf (computed only where an output stores it; its users read it themselves).
    Leaf(LoopLeaf),
    /// An operation: `op`'s kind (its operand registers meaningless) on `args`.
    Op { op: Op, args: [Arg; 3] },
}

/// A run of `count` sections of a tape, the same instructions each: iteration `i` stands
/// for the tape's instructions `start + i * len .. start + (i + 1) * len`.
#[derive(Clone, Debug, PartialEq)]
pub struct Repeat {
    pub start: usize,
    pub len: usize,
    pub count: usize,
    pub body: Vec<Step>,
    /// The outputs stored in the loop, `(t, output, step)`: body instruction `t`'s value is
    /// output `output + i * step` in iteration `i` (ordered by `t`).
    pub stores: Vec<(u32, u32, u32)>,
    /// The numbers of each iteration's own ([`LoopLeaf::Table`]), `cols` per iteration.
    pub table: Vec<f64>,
    pub cols: usize,
}

impl Repeat {
    /// The first instruction after the loop.
    pub fn end(&self) -> usize {
        self.start + self.len * self.count
    }
}

/// Fewer iterations are not worth a loop.
const MIN_COUNT: usize = 2;

fn is_leaf(op: &Op) -> bool {
    matches!(op, Op::X(_) | Op::P(_) | Op::V(_) | Op::K(_))
}

/// `op` with its operands zeroed: equal for two instructions of the same kind.
fn shape(op: Op) -> Op {
    match op {
        Op::Add(..) => Op::Add(0, 0),
        Op::Sub(..) => Op::Sub(0, 0),
        Op::Mul(..) => Op::Mul(0, 0),
        Op::Div(..) => Op::Div(0, 0),
        Op::Powf(..) => Op::Powf(0, 0),
        Op::Neg(_) => Op::Neg(0),
        Op::Powi(_, k) => Op::Powi(0, k),
        Op::Func(f, _) => Op::Func(f, 0),
        Op::MulAdd(..) => Op::MulAdd(0, 0, 0),
        Op::MulSub(..) => Op::MulSub(0, 0, 0),
        Op::NegMulAdd(..) => Op::NegMulAdd(0, 0, 0),
        leaf => leaf,
    }
}

/// `base + i * step` over the iterations, if `idx` is that.
fn affine(idx: &[u32]) -> Option<(u32, i64)> {
    let base = *idx.first()?;
    let step = idx.get(1).map_or(0, |&b| b as i64 - base as i64);
    let ok = idx
        .iter()
        .enumerate()
        .all(|(i, &k)| k as i64 == base as i64 + i as i64 * step);
    ok.then_some((base, step))
}

/// The detection's working state.
struct Finder<'t> {
    tape: &'t Tape,
    start: usize,
    len: usize,
    count: usize,
    /// The table's columns, each a value per iteration.
    columns: Vec<Vec<f64>>,
    /// Per body instruction read by the next iteration, the register read in the first.
    inits: Vec<Option<u32>>,
}

impl Finder<'_> {
    /// Register `k` of the body in iteration `i`.
    fn at(&self, i: usize, t: usize) -> usize {
        self.start + i * self.len + t
    }

    /// The leaf read in every iteration at `regs`, if they are leaves of one kind that
    /// move by a fixed step.
    fn leaf(&mut self, regs: &[usize]) -> Option<LoopLeaf> {
        let ops: Vec<Op> = regs.iter().map(|&r| self.tape.ops[r]).collect();
        let index = |f: fn(&Op) -> Option<u32>| -> Option<Vec<u32>> { ops.iter().map(f).collect() };
        Some(match ops[0] {
            Op::X(_) => {
                let (base, step) = affine(&index(|o| match *o {
                    Op::X(i) => Some(i),
                    _ => None,
                })?)?;
                LoopLeaf::X { base, step }
            }
            Op::P(_) => {
                let (base, step) = affine(&index(|o| match *o {
                    Op::P(i) => Some(i),
                    _ => None,
                })?)?;
                LoopLeaf::P { base, step }
            }
            Op::V(_) => {
                let (base, step) = affine(&index(|o| match *o {
                    Op::V(i) => Some(i),
                    _ => None,
                })?)?;
                LoopLeaf::V { base, step }
            }
            Op::K(c) => {
                let values: Vec<f64> = ops
                    .iter()
                    .map(|o| match *o {
                        Op::K(v) => Some(v),
                        _ => None,
                    })
                    .collect::<Option<_>>()?;
                if values.iter().all(|v| v.to_bits() == c.to_bits()) {
                    LoopLeaf::K(c)
                } else {
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    let known = self.columns.iter().position(|c| bits(c) == bits(&values));
                    let col = known.unwrap_or_else(|| {
                        self.columns.push(values);
                        self.columns.len() - 1
                    });
                    LoopLeaf::Table(col as u32)
                }
            }
            _ => return None,
        })
    }

    /// Operand `a` of body instruction `t`, the same in every iteration.
    fn arg(&mut self, t: usize, a: usize) -> Option<Arg> {
        let regs: Vec<usize> = (0..self.count)
            .map(|i| operands(&self.tape.ops[self.at(i, t)]).0[a] as usize)
            .collect();
        if is_leaf(&self.tape.ops[regs[0]]) {
            return self.leaf(&regs).map(Arg::Leaf);
        }
        if regs.iter().any(|&r| is_leaf(&self.tape.ops[r])) {
            return None;
        }
        // the class in the second iteration, checked in every later one
        let class = |i: usize, r: usize| -> Option<Arg> {
            let here = self.at(i, 0);
            if r >= here {
                Some(Arg::Body((r - here) as u32))
            } else if i > 0 && r >= here - self.len {
                Some(Arg::Prev {
                    t: (r + self.len - here) as u32,
                    init: 0,
                })
            } else if r < self.start {
                Some(Arg::Before(r as u32))
            } else {
                None
            }
        };
        let arg = class(1, regs[1])?;
        if (2..self.count).any(|i| class(i, regs[i]) != Some(arg)) {
            return None;
        }
        match arg {
            Arg::Body(k) => (regs[0] == self.at(0, k as usize)).then_some(arg),
            Arg::Before(r) => (regs[0] == r as usize).then_some(arg),
            Arg::Prev { t: k, .. } => {
                let init = regs[0];
                if init >= self.start {
                    return None;
                }
                let seen = self.inits[k as usize].get_or_insert(init as u32);
                (*seen == init as u32).then_some(Arg::Prev {
                    t: k,
                    init: init as u32,
                })
            }
            Arg::Leaf(_) => None,
        }
    }

    /// Body instruction `t`.
    fn step(&mut self, t: usize) -> Option<Step> {
        let regs: Vec<usize> = (0..self.count).map(|i| self.at(i, t)).collect();
        let op = self.tape.ops[regs[0]];
        if is_leaf(&op) {
            return self.leaf(&regs).map(Step::Leaf);
        }
        if regs.iter().any(|&r| shape(self.tape.ops[r]) != shape(op)) {
            return None;
        }
        let (_, count) = operands(&op);
        let mut args = [Arg::Leaf(LoopLeaf::K(0.0)); 3];
        for (a, slot) in args.iter_mut().enumerate().take(count) {
            *slot = self.arg(t, a)?;
        }
        Some(Step::Op {
            op: shape(op),
            args,
        })
    }

    /// The outputs stored in the loop (`by_reg`: every `(register, output)`, sorted).
    fn stores(&self, by_reg: &[(u32, u32)]) -> Option<Vec<(u32, u32, u32)>> {
        let head = self.tape.head() as u32;
        let outs = |r: usize| -> &[(u32, u32)] {
            let lo = by_reg.partition_point(|&(g, _)| (g as usize) < r);
            let hi = by_reg.partition_point(|&(g, _)| (g as usize) <= r);
            &by_reg[lo..hi]
        };
        let mut stores = Vec::new();
        for t in 0..self.len {
            let first = outs(self.at(0, t));
            let lists: Vec<&[(u32, u32)]> = (0..self.count).map(|i| outs(self.at(i, t))).collect();
            if lists.iter().any(|l| l.len() != first.len()) {
                return None;
            }
            for k in 0..first.len() {
                let idx: Vec<u32> = lists.iter().map(|l| l[k].1).collect();
                let (base, step) = affine(&idx)?;
                let same_side = idx.iter().all(|&o| (o < head) == (base < head));
                if step < 0 || !same_side {
                    return None;
                }
                stores.push((t as u32, base, step as u32));
            }
        }
        Some(stores)
    }

    /// Whether the instructions after the loop read of it only the last iteration.
    fn after_ok(&self) -> bool {
        let end = self.start + self.len * self.count;
        let last = end - self.len;
        self.tape.ops[end..].iter().all(|op| {
            let (args, count) = operands(op);
            args[..count].iter().all(|&q| {
                let q = q as usize;
                q < self.start || q >= last || is_leaf(&self.tape.ops[q])
            })
        })
    }
}

impl Tape {
    /// The longest run of repeating interior sections ([`Repeat`]), if the tape marks its
    /// sections and some repeat (at least two); `None` otherwise.
    pub fn repeat(&self) -> Option<Repeat> {
        let s = &self.sections;
        if s.len() < 4 || s.windows(2).any(|w| w[0] > w[1]) {
            return None;
        }
        let n = s.len() - 1;
        // the first interior sections may differ from the rest (a number first used there),
        // and the last ones (the last section builds its inflow itself, so the one before it
        // computes less for it): the longest run first
        let mut runs: Vec<(usize, usize)> = (1..4.min(n))
            .flat_map(|first| (n.saturating_sub(5)..n - 1).map(move |last| (first, last)))
            .filter(|&(first, last)| last >= first)
            .collect();
        runs.sort_by_key(|&(first, last)| std::cmp::Reverse(last - first));
        runs.into_iter()
            .find_map(|(first, last)| self.repeat_from(first, last))
    }

    /// Sections `first..=last` as one loop, if they repeat.
    fn repeat_from(&self, first: usize, last: usize) -> Option<Repeat> {
        let s = &self.sections;
        if last < first || last + 1 - first < MIN_COUNT {
            return None;
        }
        let (start, len) = (s[first] as usize, (s[first + 1] - s[first]) as usize);
        if len == 0 || (first..=last).any(|j| (s[j + 1] - s[j]) as usize != len) {
            return None;
        }
        let mut f = Finder {
            tape: self,
            start,
            len,
            count: last + 1 - first,
            columns: Vec::new(),
            inits: vec![None; len],
        };
        let body = (0..len).map(|t| f.step(t)).collect::<Option<Vec<_>>>()?;
        let mut by_reg: Vec<(u32, u32)> = (0..self.outputs.len() as u32)
            .map(|k| (self.outputs[k as usize], k))
            .collect();
        by_reg.sort_unstable();
        let stores = f.stores(&by_reg)?;
        if !f.after_ok() {
            return None;
        }
        let cols = f.columns.len();
        let table = (0..f.count)
            .flat_map(|i| f.columns.iter().map(move |c| c[i]))
            .collect();
        Some(Repeat {
            start,
            len,
            count: f.count,
            body,
            stores,
            table,
            cols,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` sections: `out_j = (x[j] - carried) * p0`, carried the previous section's
    /// difference (the number 1 before the first); section `j`'s index as a number.
    fn chain(n: usize) -> Tape {
        let mut ops = vec![Op::P(0), Op::K(1.0)];
        let (mut outputs, mut sections) = (Vec::new(), Vec::new());
        let mut carried = 1u32;
        for j in 0..n {
            let s = ops.len() as u32;
            sections.push(s);
            ops.extend([
                Op::X(j as u32),
                Op::Sub(s, carried),
                Op::K(j as f64),
                Op::Mul(s + 1, 0),
                Op::Mul(s + 3, s + 2),
            ]);
            outputs.extend([s + 3, s + 4]);
            carried = s + 1;
        }
        sections.push(ops.len() as u32);
        Tape {
            ops,
            outputs,
            split: None,
            sections,
        }
    }

    /// An operand slot an instruction does not use.
    const UNUSED: Arg = Arg::Leaf(LoopLeaf::K(0.0));

    #[test]
    fn the_interior_sections_are_one_body() {
        let t = chain(10);
        let r = t.repeat().expect("sections 1..=8 repeat");
        assert_eq!((r.start, r.len, r.count, r.cols), (7, 5, 8, 1));
        assert_eq!(r.body[0], Step::Leaf(LoopLeaf::X { base: 1, step: 1 }));
        let prev = Arg::Prev { t: 1, init: 3 };
        let sub = Step::Op {
            op: Op::Sub(0, 0),
            args: [Arg::Leaf(LoopLeaf::X { base: 1, step: 1 }), prev, UNUSED],
        };
        assert_eq!(r.body[1], sub);
        assert_eq!(
            r.body[3].clone(),
            Step::Op {
                op: Op::Mul(0, 0),
                args: [
                    Arg::Body(1),
                    Arg::Leaf(LoopLeaf::P { base: 0, step: 0 }),
                    UNUSED,
                ],
            }
        );
        // outputs 2j and 2j + 1 of section j: 2 and 3 in the first iteration, step 2
        assert_eq!(r.stores, vec![(3, 2, 2), (4, 3, 2)]);
        assert_eq!(r.table, (1..9).map(|j| j as f64).collect::<Vec<_>>());
    }

    #[test]
    fn sections_that_differ_do_not_repeat() {
        let mut t = chain(10);
        // section 6 reads the first section's difference instead of the previous one's
        let s6 = t.sections[6] as usize;
        t.ops[s6 + 1] = Op::Sub(s6 as u32, 3);
        let r = t.repeat().expect("sections 1..=5 still repeat");
        assert_eq!((r.start, r.count, r.end()), (7, 5, s6));
        let mut t = chain(10);
        t.sections.clear();
        assert_eq!(t.repeat(), None, "no sections marked");
        assert_eq!(chain(3).repeat(), None, "one interior section");
    }
}
