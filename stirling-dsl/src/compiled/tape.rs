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
}

/// A straight-line program: its instructions and the registers holding its outputs.
#[derive(Clone, Debug, Default)]
pub struct Tape {
    pub ops: Vec<Op>,
    pub outputs: Vec<u32>,
}

impl Tape {
    /// The tape computing `roots` of `arena` (leaves as [`Leaf`] encodes them).
    pub(crate) fn new(arena: &Arena, roots: &[Id]) -> Tape {
        let seen = arena.reachable(roots);
        let mut reg = vec![u32::MAX; arena.len()];
        let mut ops = Vec::new();
        for i in 0..arena.len() {
            if !seen[i] {
                continue;
            }
            let r = |c: Id| reg[c.index()];
            let op = match *arena.node(Id(i as u32)) {
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
        let outputs = roots.iter().map(|r| reg[r.index()]).collect();
        Tape { ops, outputs }
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
