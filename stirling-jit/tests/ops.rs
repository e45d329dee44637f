//! Every instruction of a tape, compiled, against the interpreter: the same bits.

use stirling_dsl::compiled::Runner;
use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;
use stirling_jit::{CcTape, JitTape};

const FUNCS: [Func; 8] = [
    Func::Sqrt,
    Func::Ln,
    Func::Exp,
    Func::Tanh,
    Func::Abs,
    Func::Sign,
    Func::Sin,
    Func::Cos,
];

/// A tape using every instruction on `x[0], x[1], p[0], v[0]`, each register an output.
fn tape() -> Tape {
    let mut ops = vec![Op::X(0), Op::X(1), Op::P(0), Op::V(0), Op::K(0.375)];
    for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 4), (0, 4)] {
        ops.extend([Op::Add(a, b), Op::Sub(a, b), Op::Mul(a, b), Op::Div(a, b)]);
        ops.push(Op::Powf(a, b));
        let c = (a + b + 1) % 5;
        ops.extend([
            Op::MulAdd(a, b, c),
            Op::MulSub(a, b, c),
            Op::NegMulAdd(a, b, c),
        ]);
    }
    for a in 0..5 {
        ops.push(Op::Neg(a));
        for k in [-7, -2, -1, 0, 1, 2, 3, 5, 8, 13, 31] {
            ops.push(Op::Powi(a, k));
        }
        for f in FUNCS {
            ops.push(Op::Func(f, a));
        }
    }
    let outputs = (0..ops.len() as u32).collect();
    straight(ops, outputs)
}

fn same(x: &[f64], p: &[f64], v: &[f64]) {
    let t = tape();
    for chunk in [usize::MAX, 7] {
        same_chunked(&t, chunk, x, p, v);
    }
    same_cc(&cc(&t), &t, x, p, v);
}

/// `t` compiled by the C compiler (the machines the tests run on have one: Rust links with it).
fn cc(t: &Tape) -> CcTape {
    CcTape::compile(t).expect("the C compiler compiles the tape")
}

/// The C compiler's code of `t` gives the interpreter's bits.
fn same_cc(code: &CcTape, t: &Tape, x: &[f64], p: &[f64], v: &[f64]) {
    let mut out = vec![0.0; t.outputs.len()];
    assert!(code.run(x, p, v, &mut out, &mut []));
    agree(t, &out, x, p, v);
}

/// `out` holds the interpreter's bits of every output of `t` (NaN for NaN).
fn agree(t: &Tape, out: &[f64], x: &[f64], p: &[f64], v: &[f64]) {
    let mut regs = Vec::new();
    t.run(p, x, v, &mut regs);
    for (k, (a, b)) in t
        .outputs
        .iter()
        .map(|&r| regs[r as usize])
        .zip(out)
        .enumerate()
    {
        let equal = a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        assert!(
            equal,
            "op {k} {:?} at {x:?} {p:?} {v:?}: {a} vs {b}",
            t.ops[k]
        );
    }
}

/// The tape compiled as functions of at most `chunk` instructions gives the interpreter's
/// bits.
fn same_chunked(t: &Tape, chunk: usize, x: &[f64], p: &[f64], v: &[f64]) {
    let jit = JitTape::compile_chunked(t, chunk).expect("the host has a JIT");
    let mut out = vec![0.0; t.outputs.len()];
    assert!(jit.run(x, p, v, &mut out));
    agree(t, &out, x, p, v);
}

#[test]
fn every_op_gives_the_interpreters_bits() {
    let vals = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.7,
        -2.3,
        1e-300,
        3.5e7,
        f64::NAN,
        f64::INFINITY,
    ];
    for (i, &a) in vals.iter().enumerate() {
        let b = vals[(i + 3) % vals.len()];
        let c = vals[(i + 7) % vals.len()];
        same(&[a, b], &[c], &[1.25 * a - 0.5]);
    }
}

/// A tape that reads no parameter (as a folded one): compiled in the order of
/// `schedule.rs`, not the tape's, with multiply-adds whose first factor is read again later
/// (its factors then swapped); every register an output.
fn tape_without_parameters() -> Tape {
    let mut ops = vec![Op::X(0), Op::X(1), Op::X(2), Op::K(0.375), Op::K(-1.5)];
    let mut seed = 7u32;
    let mut pick = |below: usize| {
        seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
        (seed >> 8) as usize % below
    };
    for k in 0..60 {
        let n = ops.len();
        let (a, b, c) = (pick(n) as u32, pick(n) as u32, pick(n) as u32);
        ops.push(match k % 6 {
            0 => Op::MulAdd(a, b, c),
            1 => Op::NegMulAdd(a, b, c),
            2 => Op::MulSub(a, b, c),
            3 => Op::Mul(a, b),
            4 => Op::Sub(a, b),
            _ => Op::MulAdd(n as u32 - 1, b, c),
        });
    }
    let outputs = (0..ops.len() as u32).collect();
    straight(ops, outputs)
}

/// A tape of one straight stretch (no loop over sections) of `ops` with `outputs`.
fn straight(ops: Vec<Op>, outputs: Vec<u32>) -> Tape {
    Tape {
        ops,
        outputs,
        split: None,
        sections: Vec::new(),
    }
}

#[test]
fn a_tape_without_parameters_gives_the_interpreters_bits() {
    let t = tape_without_parameters();
    let code = cc(&t);
    for x in [[0.7, -2.3, 1.1], [1e-3, 3.5e2, -0.25], [0.0, -0.0, 1.0]] {
        for chunk in [usize::MAX, 7] {
            same_chunked(&t, chunk, &x, &[], &[]);
        }
        same_cc(&code, &t, &x, &[], &[]);
    }
}

#[test]
fn short_slices_are_refused_before_the_call() {
    let t = tape();
    let jit = JitTape::compile(&t).expect("the host has a JIT");
    let mut out = vec![0.0; t.outputs.len()];
    assert!(!jit.run(&[1.0], &[1.0], &[1.0], &mut out));
    assert!(!jit.run(&[1.0, 2.0], &[], &[1.0], &mut out));
    assert!(!jit.run(&[1.0, 2.0], &[1.0], &[], &mut out));
    assert!(!jit.run(&[1.0, 2.0], &[1.0], &[1.0], &mut out[1..]));
    assert!(out.iter().all(|&o| o == 0.0), "nothing written");
    assert!(jit.run(&[1.0, 2.0], &[1.0], &[1.0], &mut out));
}

/// A long tape of chained arithmetic reaching back over many instructions (so that registers
/// cross the functions' boundaries), its outputs a spread of registers in scrambled order.
fn long_tape(len: usize) -> Tape {
    let mut ops = vec![Op::X(0), Op::X(1), Op::P(0), Op::K(0.5)];
    let mut k = 4u32;
    while (k as usize) < len {
        let a = k - 1;
        let b = (k * 7919) % k;
        ops.push(match k % 6 {
            0 => Op::Add(a, b),
            1 => Op::Mul(a, b),
            2 => Op::Sub(b, a),
            3 => Op::Div(a, 3),
            4 => Op::Func(Func::Tanh, a),
            _ => Op::Neg(b),
        });
        k += 1;
    }
    let outputs = (0..len as u32).rev().step_by(3).collect();
    straight(ops, outputs)
}

#[test]
fn a_tape_cut_into_functions_gives_the_same_bits() {
    let t = long_tape(3000);
    for chunk in [1, 2, 64, 1000, 3000] {
        let jit = JitTape::compile_chunked(&t, chunk).expect("the host has a JIT");
        assert_eq!(jit.functions(), 3000usize.div_ceil(chunk));
        for x in [[0.3, -1.7], [2.0, 0.0]] {
            let p = [1.1];
            let mut regs = Vec::new();
            t.run(&p, &x, &[], &mut regs);
            let mut out = vec![0.0; t.outputs.len()];
            assert!(jit.run(&x, &p, &[], &mut out));
            for (k, o) in out.iter().enumerate() {
                let want = t.output(&regs, k);
                let equal = want.to_bits() == o.to_bits() || (want.is_nan() && o.is_nan());
                assert!(equal, "chunk {chunk}, output {k}: {want} vs {o}");
            }
        }
    }
}

#[test]
fn split_outputs_go_to_their_two_slices() {
    let mut t = long_tape(50);
    t.split = Some(5);
    let jit = JitTape::compile_chunked(&t, 16).expect("the host has a JIT");
    let (x, p) = ([0.3, -1.7], [1.1]);
    let mut regs = Vec::new();
    t.run(&p, &x, &[], &mut regs);
    let (mut head, mut tail) = (vec![0.0; 5], vec![0.0; t.outputs.len() - 5]);
    assert!(jit.run_split(&x, &p, &[], &mut head, &mut tail));
    for k in 0..t.outputs.len() {
        let got = if k < 5 { head[k] } else { tail[k - 5] };
        assert_eq!(got.to_bits(), t.output(&regs, k).to_bits(), "output {k}");
    }
    // one slot short in either slice: refused, nothing written
    let mut short = vec![0.0; tail.len() - 1];
    let mut head2 = vec![0.0; 5];
    assert!(!jit.run_split(&x, &p, &[], &mut head2, &mut short));
    assert!(!jit.run_split(&x, &p, &[], &mut head2[..4], &mut tail));
    assert!(head2.iter().all(|&v| v == 0.0));
}
