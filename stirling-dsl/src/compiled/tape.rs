//! A flat register tape: one instruction per value, each writing its own register, run in one
//! tight loop (the interpreted path, for any target; the JIT compiles the same tape).
//!
//! Built from an instantiated arena: the nodes the outputs reach, in arena order (children
//! before parents), so an instruction reads only registers written before it.

use super::instance::Leaf;
use crate::expr::{Arena, Func, Id, Node};

/// One instruction: the value of its register from earlier registers or the inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// State element `x[i]`.
    X(u32),
    /// Parameter `p[k]`.
    P(u32),
    /// A sensor's read value `v[i]`.
    V(u32),
    /// A number.
    K(f64),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    Neg(u32),
    Powi(u32, i32),
    Powf(u32, u32),
    Func(Func, u32),
    /// `a * b + c` rounded once (IEEE 754 fused multiply-add, Rust's `f64::mul_add`): only
    /// in tapes with the parameters folded in ([`Tape::fold`]), where it replaces a product
    /// used by one sum alone.
    MulAdd(u32, u32, u32),
    /// `a * b - c` rounded once (`a.mul_add(b, -c)`; negation is exact).
    MulSub(u32, u32, u32),
    /// `c - a * b` rounded once (`(-a).mul_add(b, c)`).
    NegMulAdd(u32, u32, u32),
}

/// The value of a fused instruction ([`Op::MulAdd`], [`Op::MulSub`], [`Op::NegMulAdd`]) on
/// its operands' values; `None` for any other instruction.
pub fn fused_value(op: &Op, a: f64, b: f64, c: f64) -> Option<f64> {
    match op {
        Op::MulAdd(..) => Some(a.mul_add(b, c)),
        Op::MulSub(..) => Some(a.mul_add(b, -c)),
        Op::NegMulAdd(..) => Some((-a).mul_add(b, c)),
        _ => None,
    }
}

/// A straight-line program: its instructions and the registers holding its outputs.
#[derive(Clone, Debug, Default)]
pub struct Tape {
    pub ops: Vec<Op>,
    pub outputs: Vec<u32>,
    /// Where the outputs split between two buffers ([`Runner`](super::Runner)): outputs
    /// `0..s` go to the first at their index, outputs from `s` on to the second at their
    /// index minus `s` (e.g. a right-hand side and a Jacobian's values written straight to
    /// the caller's slices); `None`: every output to the first.
    pub split: Option<usize>,
    /// Where the sections' instructions start, for a function of the rows laid out section
    /// by section (`Tape::scheduled` with groups): section `j`'s instructions are
    /// `sections[j]..sections[j + 1]`, the last entry the end of the last section (what
    /// comes before `sections[0]` is the scalar rows' part). Empty: no sections marked.
    /// [`Tape::repeat`] finds the sections that repeat from it.
    pub sections: Vec<u32>,
}

/// `node` with a negated operand folded in, if it has one, as LLVM folds it in the macro's
/// code: `-a + b` is `b - a` and `a + -b` is `a - b` by IEEE 754's definition of subtraction
/// (the same bits; a NaN's sign aside). The arena's constructors fold the other cases already.
fn fused(arena: &Arena, reg: &[u32], node: &Node) -> Option<Op> {
    let neg = |c: Id| match *arena.node(c) {
        Node::Neg(d) => Some(reg[d.index()]),
        _ => None,
    };
    match *node {
        Node::Add(a, b) => match (neg(a), neg(b)) {
            (_, Some(nb)) => Some(Op::Sub(reg[a.index()], nb)),
            (Some(na), None) => Some(Op::Sub(reg[b.index()], na)),
            (None, None) => None,
        },
        _ => None,
    }
}

/// The height of every node the roots reach (a leaf 0, else one more than its tallest
/// operand); children precede parents in the arena.
fn heights(arena: &Arena, roots: &[Id]) -> Vec<u32> {
    let seen = arena.reachable(roots);
    let mut h = vec![0u32; arena.len()];
    for i in 0..arena.len() {
        if seen[i] {
            let kids = arena.node(Id(i as u32)).children();
            h[i] = kids.iter().map(|c| h[c.index()] + 1).max().unwrap_or(0);
        }
    }
    h
}

/// The operands of an instruction (none for a leaf).
pub fn operands(op: &Op) -> ([u32; 3], usize) {
    match *op {
        Op::X(_) | Op::P(_) | Op::V(_) | Op::K(_) => ([0, 0, 0], 0),
        Op::Neg(a) | Op::Powi(a, _) | Op::Func(_, a) => ([a, 0, 0], 1),
        Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) | Op::Powf(a, b) => {
            ([a, b, 0], 2)
        }
        Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => ([a, b, c], 3),
    }
}

/// `op` with its operands renumbered by `to`.
pub(crate) fn renumber(op: Op, to: &[u32]) -> Op {
    let r = |k: u32| to[k as usize];
    match op {
        Op::Add(a, b) => Op::Add(r(a), r(b)),
        Op::Sub(a, b) => Op::Sub(r(a), r(b)),
        Op::Mul(a, b) => Op::Mul(r(a), r(b)),
        Op::Div(a, b) => Op::Div(r(a), r(b)),
        Op::Powf(a, b) => Op::Powf(r(a), r(b)),
        Op::Neg(a) => Op::Neg(r(a)),
        Op::Powi(a, k) => Op::Powi(r(a), k),
        Op::Func(f, a) => Op::Func(f, r(a)),
        Op::MulAdd(a, b, c) => Op::MulAdd(r(a), r(b), r(c)),
        Op::MulSub(a, b, c) => Op::MulSub(r(a), r(b), r(c)),
        Op::NegMulAdd(a, b, c) => Op::NegMulAdd(r(a), r(b), r(c)),
        leaf => leaf,
    }
}

/// `ops` without the instructions no output reaches, the outputs renumbered and the marks
/// (instruction positions, e.g. [`Tape::sections`]) moved to where their instructions went.
pub(crate) fn prune(ops: Vec<Op>, outputs: &[u32], marks: &[u32]) -> (Vec<Op>, Vec<u32>, Vec<u32>) {
    let mut live = vec![false; ops.len()];
    for &o in outputs {
        live[o as usize] = true;
    }
    for k in (0..ops.len()).rev() {
        if live[k] {
            let (args, count) = operands(&ops[k]);
            for &a in &args[..count] {
                live[a as usize] = true;
            }
        }
    }
    let mut to = vec![u32::MAX; ops.len()];
    let mut kept = Vec::with_capacity(ops.len());
    for (k, op) in ops.into_iter().enumerate() {
        if live[k] {
            to[k] = kept.len() as u32;
            kept.push(renumber(op, &to));
        }
    }
    let outputs = outputs.iter().map(|&o| to[o as usize]).collect();
    // a mark at `m` moves to the number of instructions kept before it
    let mut before = Vec::with_capacity(live.len() + 1);
    before.push(0u32);
    for &l in &live {
        let last = before[before.len() - 1];
        before.push(last + u32::from(l));
    }
    let marks = marks
        .iter()
        .map(|&m| before[(m as usize).min(live.len())])
        .collect();
    (kept, outputs, marks)
}

impl Tape {
    /// The tape computing `roots` of `arena` (leaves as [`Leaf`] encodes them), its
    /// instructions in arena order.
    pub(crate) fn new(arena: &Arena, roots: &[Id]) -> Tape {
        let seen = arena.reachable(roots);
        let nodes = (0..arena.len()).filter(|&i| seen[i]);
        Tape::in_order(arena, roots, nodes, &[])
    }

    /// The tape computing `roots` of `arena`, its instructions in the order a depth-first
    /// walk from the roots taken in `schedule`'s order (indices into `roots`) needs them:
    /// each value computed close to where it is used, so that native code keeps it in a
    /// register rather than spilling it (e.g. a section's right-hand side next to its
    /// Jacobian entries, which share most of their terms).
    ///
    /// `groups` (empty, or one per root, non-decreasing along `schedule`): group 0 the
    /// scalar part, group `j + 1` section `j`; the tape marks where each section's
    /// instructions start ([`Tape::sections`]).
    pub(crate) fn scheduled(
        arena: &Arena,
        roots: &[Id],
        schedule: &[usize],
        groups: &[u32],
    ) -> Tape {
        // the taller operand first (Sethi-Ullman): fewer values wait in registers meanwhile
        let height = heights(arena, roots);
        // 0: not visited, 1: children pending, 2: emitted
        let mut state = vec![0u8; arena.len()];
        let mut nodes = Vec::new();
        let mut stack: Vec<(Id, bool)> = Vec::new();
        // `marks[g]`: the position in `nodes` where group `g + 1` (section `g`) starts
        let mut marks: Vec<u32> = Vec::new();
        for &k in schedule {
            if let Some(&g) = groups.get(k) {
                while marks.len() < g as usize {
                    marks.push(nodes.len() as u32);
                }
            }
            stack.push((roots[k], false));
            while let Some((id, ready)) = stack.pop() {
                let st = &mut state[id.index()];
                if ready {
                    *st = 2;
                    nodes.push(id.index());
                    continue;
                }
                if *st != 0 {
                    continue;
                }
                *st = 1;
                stack.push((id, true));
                let mut kids = arena.node(id).children();
                kids.sort_by_key(|c| height[c.index()]);
                for &c in &kids {
                    if state[c.index()] == 0 {
                        stack.push((c, false));
                    }
                }
            }
        }
        if !marks.is_empty() {
            marks.push(nodes.len() as u32);
        }
        Tape::in_order(arena, roots, nodes.into_iter(), &marks)
    }

    /// The tape of `roots`, its instructions the nodes `nodes` (children before parents);
    /// `marks` (positions in `nodes`) become [`Tape::sections`].
    fn in_order(
        arena: &Arena,
        roots: &[Id],
        nodes: impl Iterator<Item = usize>,
        marks: &[u32],
    ) -> Tape {
        let mut reg = vec![u32::MAX; arena.len()];
        let mut ops = Vec::new();
        let mut sections = Vec::with_capacity(marks.len());
        for (at, i) in nodes.enumerate() {
            while sections.len() < marks.len() && marks[sections.len()] as usize == at {
                sections.push(ops.len() as u32);
            }
            let r = |c: Id| reg[c.index()];
            let node = arena.node(Id(i as u32));
            if let Some(op) = fused(arena, &reg, node) {
                reg[i] = ops.len() as u32;
                ops.push(op);
                continue;
            }
            let op = match *node {
                Node::Const(bits) => Op::K(f64::from_bits(bits)),
                Node::Sym(s) => match Leaf::of(s) {
                    Some(Leaf::State(k)) => Op::X(k as u32),
                    Some(Leaf::Param(k)) => Op::P(k as u32),
                    Some(Leaf::Read(k)) => Op::V(k as u32),
                    Some(Leaf::Opaque(v)) => Op::K(v as f64),
                    None => Op::K(f64::NAN),
                },
                Node::Add(a, b) => Op::Add(r(a), r(b)),
                Node::Sub(a, b) => Op::Sub(r(a), r(b)),
                Node::Mul(a, b) => Op::Mul(r(a), r(b)),
                Node::Div(a, b) => Op::Div(r(a), r(b)),
                Node::Neg(a) => Op::Neg(r(a)),
                Node::Powi(a, k) => Op::Powi(r(a), k),
                Node::Powf(a, b) => Op::Powf(r(a), r(b)),
                Node::Func(f, a) => Op::Func(f, r(a)),
                Node::Named(_, a) => {
                    reg[i] = r(a);
                    continue;
                }
            };
            reg[i] = ops.len() as u32;
            ops.push(op);
        }
        while sections.len() < marks.len() {
            sections.push(ops.len() as u32);
        }
        let outputs: Vec<u32> = roots.iter().map(|r| reg[r.index()]).collect();
        let (ops, outputs, sections) = prune(ops, &outputs, &sections);
        Tape {
            ops,
            outputs,
            split: None,
            sections,
        }
    }

    /// The number of outputs written to the first buffer ([`Tape::split`]).
    pub fn head(&self) -> usize {
        self.split
            .map_or(self.outputs.len(), |s| s.min(self.outputs.len()))
    }

    /// Run the tape: every register into `regs` (resized to fit).
    pub fn run(&self, p: &[f64], x: &[f64], v: &[f64], regs: &mut Vec<f64>) {
        regs.clear();
        regs.reserve(self.ops.len());
        for op in &self.ops {
            let g = |k: u32| regs[k as usize];
            let val = match *op {
                Op::X(i) => x[i as usize],
                Op::P(k) => p[k as usize],
                Op::V(i) => v[i as usize],
                Op::K(c) => c,
                Op::Add(a, b) => g(a) + g(b),
                Op::Sub(a, b) => g(a) - g(b),
                Op::Mul(a, b) => g(a) * g(b),
                Op::Div(a, b) => g(a) / g(b),
                Op::Neg(a) => -g(a),
                Op::Powi(a, k) => g(a).powi(k),
                Op::Powf(a, b) => g(a).powf(g(b)),
                Op::Func(f, a) => f.apply(g(a)),
                Op::MulAdd(a, b, c) | Op::MulSub(a, b, c) | Op::NegMulAdd(a, b, c) => {
                    fused_value(op, g(a), g(b), g(c)).unwrap_or(f64::NAN)
                }
            };
            regs.push(val);
        }
    }

    /// The output `k` after [`Tape::run`].
    #[inline]
    pub fn output(&self, regs: &[f64], k: usize) -> f64 {
        regs[self.outputs[k] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{At, Sym};

    /// `[-x0 + x1, x1 * x0 + -(x0 * x0), x0 * x0]` over states `x0`, `x1`.
    fn arena() -> (Arena, Vec<Id>) {
        let mut a = Arena::new();
        let x0 = a.sym(Sym::State(0, At::Scalar));
        let x1 = a.sym(Sym::State(1, At::Scalar));
        let n0 = a.neg(x0);
        let e0 = a.add(n0, x1);
        let sq = a.mul(x0, x0);
        let m = a.mul(x1, x0);
        let nsq = a.neg(sq);
        let e1 = a.add(nsq, m);
        (a, vec![e0, e1, sq])
    }

    fn want(x0: f64, x1: f64) -> [f64; 3] {
        [-x0 + x1, -(x0 * x0) + x1 * x0, x0 * x0]
    }

    #[test]
    fn negations_fold_into_their_users_with_the_same_bits() {
        let (a, roots) = arena();
        let t = Tape::new(&a, &roots);
        assert!(
            t.ops.iter().all(|o| !matches!(o, Op::Neg(_))),
            "{:?}",
            t.ops
        );
        let vals = [0.0, -0.0, 1.5, -2.25, 1e-310, f64::INFINITY, 3e300];
        let mut regs = Vec::new();
        for &x0 in &vals {
            for &x1 in &vals {
                t.run(&[], &[x0, x1], &[], &mut regs);
                for (k, w) in want(x0, x1).iter().enumerate() {
                    let got = t.output(&regs, k);
                    let same = got.to_bits() == w.to_bits() || (got.is_nan() && w.is_nan());
                    assert!(same, "output {k} at ({x0}, {x1}): {got} vs {w}");
                }
            }
        }
    }

    #[test]
    fn a_scheduled_tape_computes_the_same_outputs() {
        let (a, roots) = arena();
        let t = Tape::new(&a, &roots);
        let s = Tape::scheduled(&a, &roots, &[2, 0, 1], &[]);
        assert_eq!(s.ops.len(), t.ops.len());
        // the walk starts at the third root: `x0`, then `x0 * x0`
        assert_eq!(&s.ops[..2], &[Op::X(0), Op::Mul(0, 0)]);
        let (mut ra, mut rb) = (Vec::new(), Vec::new());
        t.run(&[], &[0.7, -1.3], &[], &mut ra);
        s.run(&[], &[0.7, -1.3], &[], &mut rb);
        for k in 0..3 {
            assert_eq!(t.output(&ra, k).to_bits(), s.output(&rb, k).to_bits());
        }
    }
}
