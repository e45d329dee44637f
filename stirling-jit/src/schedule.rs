//! The order in which a function's instructions are emitted: a greedy list schedule that
//! keeps fewer values live at once than the tape's own order.
//!
//! The tape is laid out depth first from its outputs, one section's right-hand side with its
//! Jacobian entries; the terms they share then live across long stretches (on `nsection`'s
//! folded RHS + Jacobian at n = 2, 21 values live on average and up to 39, against 16 `xmm`
//! registers), and Cranelift spills them. Here, of the instructions whose operands are
//! computed, the next emitted is the one that ends the most live values net of the one it
//! starts (an operand whose last reader it is, against its own value if anything reads it
//! later), then the one reading the most computed values, then the earliest in the tape.
//! Inputs and numbers cost nothing (loaded at each use, never live across the function);
//! nor do registers of an earlier function (read from the scratch array where used). Only the order of independent instructions changes,
//! never an operation or its operands, so the results are the same bits.

use std::ops::Range;

use stirling_dsl::compiled::{operands, Op};

use crate::build::leaf;

/// The instructions `range` of `ops` in the order to emit them (each after its operands).
pub(crate) fn order(ops: &[Op], range: Range<usize>) -> Vec<usize> {
    let start = range.start;
    let len = range.len();
    // an operand counts when it is computed in this range (not a leaf, not earlier)
    let inside = |q: usize| q >= start && q < range.end && !leaf(&ops[q]);
    // per instruction: its distinct counted operands
    let args: Vec<Vec<usize>> = range
        .clone()
        .map(|k| {
            let (a, count) = operands(&ops[k]);
            let mut v: Vec<usize> = a[..count]
                .iter()
                .map(|&q| q as usize)
                .filter(|&q| inside(q))
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        })
        .collect();
    let mut readers: Vec<Vec<usize>> = vec![Vec::new(); len];
    for (i, a) in args.iter().enumerate() {
        for &q in a {
            readers[q - start].push(i);
        }
    }
    // `left[i]`: readers of `i` not emitted yet; `waiting[i]`: operands of `i` not emitted yet
    let mut left: Vec<usize> = readers.iter().map(Vec::len).collect();
    let mut waiting: Vec<usize> = args.iter().map(Vec::len).collect();
    let mut ready: Vec<usize> = (0..len).filter(|&i| waiting[i] == 0).collect();
    let mut out = Vec::with_capacity(len);
    while !ready.is_empty() {
        let score = |i: usize| -> i64 {
            let ends = args[i].iter().filter(|&&q| left[q - start] == 1).count() as i64;
            let starts = i64::from(left[i] > 0);
            // the values ended net of the one started first; among equals, the instruction
            // reading more computed values (measured on `nsection`'s folded RHS + Jacobian:
            // n = 2, 61 to 56 ns; n = 10, 129 to 121 ns; the net count alone: 63 and 124)
            WEIGHT * (ends - starts) + args[i].len() as i64
        };
        // the best score, the earliest instruction among equals
        let mut best = 0;
        for j in 1..ready.len() {
            let (a, b) = (ready[j], ready[best]);
            let (sa, sb) = (score(a), score(b));
            if sa > sb || (sa == sb && a < b) {
                best = j;
            }
        }
        let i = ready.swap_remove(best);
        out.push(start + i);
        for &q in &args[i] {
            left[q - start] -= 1;
        }
        for &r in &readers[i] {
            waiting[r] -= 1;
            if waiting[r] == 0 {
                ready.push(r);
            }
        }
    }
    debug_assert_eq!(out.len(), len);
    out
}

/// How much a value ended or started weighs against a computed operand read (more than the
/// three operands an instruction reads at most: the net count decides first).
const WEIGHT: i64 = 4;

#[cfg(test)]
mod tests {
    use super::*;

    /// Two long chains read one value computed first and one at the end: the schedule keeps
    /// every instruction after its operands and emits each exactly once.
    #[test]
    fn every_instruction_once_after_its_operands() {
        let mut ops = vec![Op::X(0), Op::X(1), Op::Mul(0, 1)];
        for k in 0..20u32 {
            let prev = if k == 0 { 2 } else { ops.len() as u32 - 1 };
            ops.push(Op::Add(prev, k % 2));
        }
        let n = ops.len() as u32;
        ops.push(Op::Mul(2, n - 1));
        let order = order(&ops, 0..ops.len());
        let mut at = vec![usize::MAX; ops.len()];
        for (i, &k) in order.iter().enumerate() {
            assert_eq!(at[k], usize::MAX, "{k} twice");
            at[k] = i;
        }
        for (k, op) in ops.iter().enumerate() {
            let (a, c) = operands(op);
            for &q in &a[..c] {
                assert!(at[q as usize] < at[k], "{q} after its reader {k}");
            }
        }
    }

    /// The most values computed and still to be read at once, emitting `ops` in `order`.
    fn most_live(ops: &[Op], order: &[usize]) -> usize {
        let mut last = vec![0; ops.len()];
        for (i, &k) in order.iter().enumerate() {
            let (a, c) = operands(&ops[k]);
            for &q in &a[..c] {
                last[q as usize] = i;
            }
        }
        let mut at = vec![0; ops.len()];
        for (i, &k) in order.iter().enumerate() {
            at[k] = i;
        }
        (0..order.len())
            .map(|i| {
                (0..ops.len())
                    .filter(|&q| !leaf(&ops[q]) && at[q] < i && last[q] >= i)
                    .count()
            })
            .max()
            .unwrap_or(0)
    }

    /// Twenty products computed first and each read once at the end: in the tape's order all
    /// twenty are live at once, scheduled each is read as soon as it is computed.
    #[test]
    fn values_are_read_soon_after_they_are_computed() {
        let mut ops = vec![Op::X(0), Op::K(3.0)];
        for _ in 0..20 {
            ops.push(Op::Mul(0, 1));
        }
        for k in 0..20 {
            ops.push(Op::Add(2 + k, 0));
        }
        let tape: Vec<usize> = (0..ops.len()).collect();
        assert_eq!(most_live(&ops, &tape), 20);
        assert_eq!(most_live(&ops, &order(&ops, 0..ops.len())), 1);
    }
}
