//! Tapes whose sections repeat, compiled with a loop over them ([`JitTape::compile`] finds
//! the run with `Tape::repeat`) against the same tape unrolled and the interpreter: the
//! same bits at every output, and the loop's code the same size at any `n`.

use stirling_dsl::compiled::{Op, Tape};
use stirling_dsl::expr::Func;
use stirling_jit::{JitTape, LOOP_MIN};

/// A chain of `n` sections, as a function of the rows lays them out: a scalar part (the
/// parameters' terms), then per section `j` its state's terms, a value carried from the
/// previous section (a link), the section's index as a number, a `tanh` and an output per
/// row in each of the two buffers (a right-hand side and a Jacobian's values), and two outputs
/// per section of values computed before the sections. The first
/// and last sections differ (a number folded in, as the variants of a row do).
fn chain(n: usize) -> Tape {
    let mut ops = vec![Op::P(0), Op::P(1), Op::K(0.5)];
    ops.push(Op::Mul(0, 1)); // 3: p0 * p1, read by every section
    let mut outputs = Vec::new();
    let mut tail = Vec::new();
    let mut sections = Vec::new();
    let mut carried = 2u32; // section 0 reads the number 0.5
    for j in 0..n {
        sections.push(ops.len() as u32);
        let r = |ops: &Vec<Op>| ops.len() as u32;
        let x = r(&ops);
        ops.push(Op::X(j as u32));
        let xn = r(&ops);
        ops.push(Op::X(((j + 1) % n) as u32));
        let d = r(&ops);
        ops.push(Op::Sub(xn, x));
        let f = r(&ops);
        ops.push(Op::Mul(d, 3));
        let idx = r(&ops);
        let index = if j == 0 { 0.0 } else { j as f64 + 0.25 };
        ops.push(Op::K(index));
        let a = r(&ops);
        ops.push(Op::Add(f, carried));
        let s = r(&ops);
        ops.push(Op::Mul(a, idx));
        let t = r(&ops);
        ops.push(Op::Func(Func::Tanh, s));
        let q = r(&ops);
        ops.push(Op::Div(t, 0));
        outputs.push(q);
        tail.push(a);
        tail.push(f);
        // a value from before the sections and a number, an output of every section (as a
        // Jacobian entry the same in each): the loop stores them (`looped::spread`)
        tail.push(3);
        tail.push(2);
        carried = f;
    }
    sections.push(ops.len() as u32);
    // after the sections: a scalar row reading the last section's link
    let last = ops.len() as u32;
    ops.push(Op::Add(carried, 3));
    outputs.push(last);
    let split = outputs.len();
    outputs.extend(tail);
    Tape {
        ops,
        outputs,
        split: Some(split),
        sections,
    }
}

fn outputs_of(code: &JitTape, tape: &Tape, x: &[f64], p: &[f64]) -> Vec<f64> {
    let mut out = vec![f64::NAN; tape.outputs.len()];
    assert!(code.run(x, p, &[], &mut out));
    out
}

#[test]
fn the_looped_code_gives_the_unrolled_codes_and_the_interpreters_bits() {
    for n in [4, 5, 10, 100] {
        let tape = chain(n);
        let rep = tape.repeat().expect("the interior sections repeat");
        assert_eq!(
            (rep.count, rep.cols),
            (n - 2, 1),
            "sections 1..=n-2 at n = {n}"
        );
        let looped = JitTape::compile_looped(&tape, &rep).unwrap();
        assert!(looped.looped(), "n = {n}");
        // `compile` loops from `LOOP_MIN` iterations on
        let chosen = JitTape::compile(&tape).unwrap();
        assert_eq!(chosen.looped(), rep.count >= LOOP_MIN, "n = {n}");
        let unrolled = JitTape::compile_chunked(&tape, usize::MAX).unwrap();
        assert!(!unrolled.looped());
        let p = [1.3, -0.7];
        let mut regs = Vec::new();
        for s in 0..5 {
            let x: Vec<f64> = (0..n)
                .map(|i| ((i * 7 + s) as f64 * 0.37).sin() * 40.0)
                .collect();
            let a = outputs_of(&looped, &tape, &x, &p);
            let b = outputs_of(&unrolled, &tape, &x, &p);
            tape.run(&p, &x, &[], &mut regs);
            for k in 0..a.len() {
                let want = tape.output(&regs, k);
                assert_eq!(a[k].to_bits(), want.to_bits(), "n = {n}, output {k}");
                assert_eq!(b[k].to_bits(), want.to_bits(), "n = {n}, output {k}");
            }
        }
    }
}

#[test]
fn the_looped_code_does_not_grow_with_n() {
    let size = |n: usize| {
        let tape = chain(n);
        let rep = tape.repeat().expect("the interior sections repeat");
        JitTape::compile_looped(&tape, &rep).unwrap().code_bytes()
    };
    let unrolled = |n: usize| {
        JitTape::compile_chunked(&chain(n), usize::MAX)
            .unwrap()
            .code_bytes()
    };
    let (s10, s1000) = (size(10), size(1000));
    // the same code but for the immediates (the iteration count, offsets) at n = 1000
    assert!(
        s1000 <= s10 + 64,
        "the loop's code: {s10} bytes at n = 10, {s1000} at 1000"
    );
    assert!(unrolled(1000) > 20 * s1000, "{} vs {s1000}", unrolled(1000));
}

#[test]
fn a_tape_whose_sections_differ_is_compiled_unrolled() {
    let mut tape = chain(10);
    // section 5 reads the state of section 0: no longer the same step as the others
    let s5 = tape.sections[5] as usize;
    tape.ops[s5] = Op::X(0);
    let code = JitTape::compile(&tape).unwrap();
    let p = [0.4, 2.0];
    let x: Vec<f64> = (0..10).map(|i| i as f64 - 3.5).collect();
    let out = outputs_of(&code, &tape, &x, &p);
    let mut regs = Vec::new();
    tape.run(&p, &x, &[], &mut regs);
    for (k, o) in out.iter().enumerate() {
        assert_eq!(o.to_bits(), tape.output(&regs, k).to_bits(), "output {k}");
    }
    // the loop (if any) stops before section 5 or starts after it
    let rep = tape.repeat();
    assert_eq!(code.looped(), rep.is_some());
    if let Some(rep) = rep {
        assert!(rep.end() <= s5 || rep.start > s5, "{rep:?}");
    }
}
