//! The JIT's loop over the repeating interior sections (`Tape::repeat`, `stirling-jit`'s
//! looped code) on the family's files: found at every n with interior sections to repeat,
//! its code the same size at n = 30 and 100 (unrolled, it grew with n), and its results the
//! interpreter's bits (`files_jit` checks every function of every file at n = 10 and 100;
//! here the right-hand side with the Jacobian, with the parameters as inputs and folded in).

use std::path::Path;

use stirling::dsl::compiled::CompiledModel;
use stirling::dsl::{Closure, Model};
use stirling::models::files;

fn model(name: &str, n: usize) -> CompiledModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(format!("{name}.stirling"));
    let def = files::definition(&path).expect("the family's file loads");
    files::jit(def.model(n, Closure::Full).expect("compiles at n"))
}

/// RHS and Jacobian values of `m` at `(p, x)`.
fn values(m: &dyn Model, p: &[f64], x: &[f64]) -> Vec<f64> {
    let mut f = vec![0.0; m.n_states()];
    let mut v = vec![0.0; m.jacobian_pattern(p).len()];
    m.rhs_and_jacobian_values(p, x, 0.0, &mut f, &mut v);
    f.extend(v);
    f
}

#[test]
fn the_interior_sections_run_as_one_loop() {
    for name in ["nsection", "nsection_fx", "nsection_ext"] {
        let mut bytes = Vec::new();
        for n in [30, 100] {
            let m = model(name, n);
            let p = m.default_params();
            let rep = m.rhs_jacobian_tape(&p).repeat();
            let rep = rep.unwrap_or_else(|| panic!("{name} at n = {n}: no repeating sections"));
            assert!(
                rep.count >= n - 4,
                "{name} at n = {n}: {} iterations",
                rep.count
            );
            let code = m.rhs_jacobian_code(&p).expect("the JIT compiles the tape");
            assert!(code.looped(), "{name} at n = {n}: compiled unrolled");
            bytes.push(code.code_bytes().unwrap_or(usize::MAX));
            let folded = m.folded(&p);
            let fcode = folded
                .rhs_jacobian_code(&p)
                .expect("the folded tape compiles");
            assert!(
                fcode.looped(),
                "{name} folded at n = {n}: compiled unrolled"
            );
            // the looped code against the interpreter, bit for bit
            let x: Vec<f64> = (0..m.n_states())
                .map(|i| 1.0 + 0.01 * ((i * 13) % 7) as f64)
                .collect();
            let x = {
                let mut s = x;
                let guess = {
                    let mut g = vec![0.0; m.n_states()];
                    m.equilibrium_guess(&p, &mut g);
                    g
                };
                for (a, g) in s.iter_mut().zip(guess) {
                    *a *= g;
                }
                s
            };
            let interp = model(name, n).interpreted();
            // the folded code against the interpreter's folded tape (its multiply-adds are
            // fused: not the bits of the tape with the parameters as inputs)
            let folded_interp = interp.folded(&p);
            for (what, got, want) in [
                ("jit", values(&m, &p, &x), values(&interp, &p, &x)),
                (
                    "folded",
                    values(&folded, &p, &x),
                    values(&folded_interp, &p, &x),
                ),
            ] {
                for (k, (a, b)) in got.iter().zip(&want).enumerate() {
                    let same = a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
                    assert!(same, "{name} {what} at n = {n}, output {k}: {a} vs {b}");
                }
            }
        }
        assert!(
            bytes[1] < bytes[0] * 2,
            "{name}: code of {} bytes at n = 100 against {} at n = 30",
            bytes[1],
            bytes[0]
        );
    }
}
