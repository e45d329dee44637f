//! The JIT (`stirling-jit`, installed by `models::files` under the default `jit` feature)
//! against the tape interpreter, on every family file at n = 1, 2, 10, 100, both closures,
//! at random states and parameters: every output of every function the same bits (1e-15
//! relative is the bound asked; the two run the same IEEE operations in the same order),
//! with the parameters as inputs and folded in. The interpreter alone (the path of targets
//! without a JIT) is the model too: `files_family` tests it against the macro's code.

mod common;

use std::path::Path;

use common::{random_state, rng, Spread};
use rand::Rng;
use stirling::dsl::compiled::CompiledModel;
use stirling::dsl::{Closure, Model};
use stirling::models::files;

const FILES: [&str; 6] = [
    "schmidt",
    "cv1",
    "cv2",
    "nsection",
    "nsection_fx",
    "nsection_ext",
];

fn file(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(format!("{name}.stirling"))
}

/// Every numeric output of `m` at `(p, x)`, in a fixed order.
fn outputs(m: &dyn Model, p: &[f64], x: &[f64]) -> Vec<f64> {
    let n = m.n_states();
    let nnz = m.jacobian_pattern(p).len();
    let (mut f, mut vals) = (vec![0.0; n], vec![0.0; nnz]);
    let mut all = Vec::new();
    m.rhs(p, x, 0.0, &mut f);
    all.extend(&f);
    m.jacobian_values(p, x, 0.0, &mut vals);
    all.extend(&vals);
    m.rhs_and_jacobian_values(p, x, 0.0, &mut f, &mut vals);
    all.extend(&f);
    all.extend(&vals);
    all.extend(m.jacobian_dense(p, x, 0.0));
    all.extend(m.param_jacobian_dense(p, x, 0.0));
    let nb = m.bodies().len();
    let mut g = vec![0.0; nb];
    m.pressure_forces(p, x, &mut g);
    all.extend(&g);
    for k in 0..nb {
        let mut d = vec![0.0; n];
        m.pressure_force_gradient(k, p, x, &mut d);
        all.extend(&d);
    }
    m.body_masses(p, &mut g);
    all.extend(&g);
    m.equilibrium_guess(p, &mut f);
    all.extend(&f);
    let pw = m.power(p, x);
    all.extend([m.energy(p, x), m.gas_mass(p, x), pw.heat, pw.boundary]);
    all.push(pw.mechanical);
    let nv = m.vessel_names().len();
    let (mut pr, mut vol, mut t) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    m.pv(p, x, &mut pr, &mut vol);
    m.temperatures(p, x, &mut t);
    all.extend(pr.iter().chain(&vol).chain(&t));
    for k in 0..m.sensors().len() {
        let v: Vec<f64> = x.iter().take(3).copied().collect();
        let (mut dv, mut dp) = (vec![0.0; 3], vec![0.0; p.len()]);
        all.push(m.sensor_output(k, p, &v, &mut dv, &mut dp));
        all.extend(dv.iter().chain(&dp));
    }
    all
}

/// The largest relative difference (0 for the same bits, NaN against NaN included).
fn worst(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            if x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()) {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs())
            }
        })
        .fold(0.0, f64::max)
}

fn check(name: &str, n: usize, jit: &CompiledModel, interp: &CompiledModel, p: &[f64], x: &[f64]) {
    let w = worst(&outputs(jit, p, x), &outputs(interp, p, x));
    assert!(w <= 1e-15, "{name} n = {n}: JIT differs by {w:e}");
}

#[test]
fn jit_is_the_interpreter_on_every_family_file() {
    for name in FILES {
        let def = files::definition(&file(name)).unwrap_or_else(|e| panic!("{e}"));
        let ns: &[usize] = if def.has_array() {
            &[1, 2, 10, 100]
        } else {
            &[1]
        };
        for &n in ns {
            for closure in [Closure::Full, Closure::Frozen] {
                let interp = def.model(n, closure).unwrap();
                let jit = files::jit(def.model(n, closure).unwrap());
                assert!(jit.has_jit() && !interp.has_jit());
                let mut r = rng(n as u64 * 13 + 5);
                for k in 0..3 {
                    let mut p = interp.default_params();
                    if k > 0 {
                        p.iter_mut()
                            .for_each(|v| *v *= 1.0 + 0.1 * r.gen_range(-1.0..1.0));
                    }
                    let spread = [Spread::Wide, Spread::Balanced][k % 2];
                    let x = random_state(&interp, &p, spread, &mut r);
                    check(name, n, &jit, &interp, &p, &x);
                    // folded in: the JIT's folded code against the interpreter's folded tape
                    // (with the parameters as inputs the folded model is not the same bits:
                    // its multiply-adds are fused, `files_family` bounds it against the macro)
                    let (jf, inf) = (jit.folded(&p), interp.folded(&p));
                    check(name, n, &jf, &inf, &p, &x);
                    assert!(jf.native_tapes() > 0, "{name} n = {n}: folded ran natively");
                    if n <= 2 && k == 0 && matches!(closure, Closure::Full) {
                        the_c_compilers_code_and_kernel(name, n, &jit, &inf, (&p, &x));
                    }
                }
                assert_eq!(interp.native_tapes(), 0);
                assert!(
                    jit.native_tapes() >= 8,
                    "{name} n = {n}: only {} tapes ran as native code",
                    jit.native_tapes()
                );
            }
        }
    }
}

/// The folded model of the C compiler's code (`files::folded_native`) gives the interpreter's
/// folded bits, and its kernel gives that model's RHS + Jacobian bits.
fn the_c_compilers_code_and_kernel(
    name: &str,
    n: usize,
    jit: &CompiledModel,
    interp_folded: &CompiledModel,
    (p, x): (&[f64], &[f64]),
) {
    let cf = files::folded_native(jit, p);
    check(name, n, &cf, interp_folded, p, x);
    let kernel = cf
        .kernel()
        .expect("a folded model's RHS + Jacobian runs natively");
    let (mut f, mut v) = (vec![0.0; cf.n_states()], vec![0.0; kernel.nnz()]);
    kernel.rhs_and_jacobian_values(x, &mut f, &mut v).unwrap();
    let (mut g, mut w) = (f.clone(), v.clone());
    cf.rhs_and_jacobian_values(p, x, 0.0, &mut g, &mut w);
    let bits = |a: &[f64]| a.iter().map(|z| z.to_bits()).collect::<Vec<_>>();
    assert_eq!(
        (bits(&f), bits(&v)),
        (bits(&g), bits(&w)),
        "{name} n = {n}: kernel"
    );
    // wrong lengths are an error that says them, nothing written
    let e = kernel
        .rhs_and_jacobian_values(&x[1..], &mut f, &mut v)
        .unwrap_err();
    assert_eq!((e.x, e.n_states), (x.len() - 1, x.len()));
    assert!(e.to_string().contains("called with x of"));
}

#[test]
fn the_interpreter_is_the_fallback() {
    // a model whose JIT is taken away runs every function on the interpreter, unchanged
    let def = files::definition(&file("nsection")).unwrap();
    let jit = files::jit(def.model(10, Closure::Full).unwrap());
    let p = jit.default_params();
    let x = random_state(&jit, &p, Spread::Wide, &mut rng(3));
    let a = outputs(&jit, &p, &x);
    let interp = jit.interpreted();
    assert!(!interp.has_jit());
    assert_eq!(worst(&a, &outputs(&interp, &p, &x)), 0.0);
    assert_eq!(interp.native_tapes(), 0);
}

#[test]
fn short_slices_are_the_interpreters_panic_not_a_wild_write() {
    // the native code refuses slices shorter than its tape before running; the interpreter
    // then indexes out of bounds as the macro's code does
    let def = files::definition(&file("cv1")).unwrap();
    let jit = files::jit(def.model(1, Closure::Full).unwrap());
    let p = jit.default_params();
    let x = vec![0.0; jit.n_states() - 1];
    let mut f = vec![0.0; jit.n_states()];
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        jit.rhs(&p, &x, 0.0, &mut f);
    }));
    assert!(r.is_err());
}
