//! Every instruction of a tape, compiled, against the interpreter: the same bits.

use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;
use stirling_jit::JitTape;

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
    Tape { ops, outputs }
}

fn same(x: &[f64], p: &[f64], v: &[f64]) {
    let t = tape();
    let jit = JitTape::compile(&t).expect("the host has a JIT");
    let mut regs = Vec::new();
    t.run(p, x, v, &mut regs);
    let mut out = vec![0.0; t.outputs.len()];
    assert!(jit.run(x, p, v, &mut out));
    for (k, (a, b)) in regs.iter().zip(&out).enumerate() {
        let equal = a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        assert!(
            equal,
            "op {k} {:?} at {x:?} {p:?} {v:?}: {a} vs {b}",
            t.ops[k]
        );
    }
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
