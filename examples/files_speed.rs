//! Engines from files, timed: the load and compile time of `examples/engines/nsection.stirling`
//! (read, compose, check, lower, assemble, differentiate, lay out the tapes at `n`, compile
//! the right-hand side with the Jacobian to native code), and the right-hand side with the
//! sparse Jacobian's values (`Model::rhs_and_jacobian_values`) of the macro's `nsection`, the
//! file's tape interpreted, the tape compiled by the JIT (`stirling-jit`) and the JIT with the
//! parameters folded in, at the benchmarks' fairness state (`examples/support/fairness.rs`,
//! as `examples/bench_native.rs` and CasADi's side of `bench/`).
//!
//! With the parameters folded in, three ways: the folded tapes compiled by Cranelift, by the
//! system's C compiler where it pays (`files::folded_native`, `stirling_jit::cc_jit`), both
//! called through the `Model` trait (which checks the parameters at each call), and that
//! model's kernel (`CompiledModel::kernel`: the state alone, like CasADi's literal C).
//!
//! The kernels are timed in alternating rounds (each of them in turn, three times; each keeps
//! its fastest round's median), so that a busy machine slows them alike.
//!
//! Run: `cargo run --release --example files_speed [-- --ns 2,10,100,1000] [--json]`
//! (`--json`: the numbers, with the state, right-hand side and Jacobian of the folded model
//! for `bench/files_compare.py`'s check against CasADi).

#[path = "support/fairness.rs"]
mod fairness;

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use fairness::{fairness_state, time_per_call};
use serde_json::{json, Value};
use stirling::dsl::compiled::{CompiledModel, Definition, Kernel, KernelError};
use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::files;

/// Seconds per call of RHS + Jacobian values at `x` (the median of batches of ~2 ms).
fn time(m: &dyn Model, p: &[f64], x: &[f64]) -> f64 {
    let mut f = vec![0.0; m.n_states()];
    let mut v = vec![0.0; m.jacobian_pattern(p).len()];
    let once = || {
        m.rhs_and_jacobian_values(
            std::hint::black_box(p),
            std::hint::black_box(x),
            0.0,
            &mut f,
            &mut v,
        )
    };
    time_per_call(once, 2e-3, 21, 0.6).0
}

/// Seconds per call of the folded model's kernel (`CompiledModel::kernel`: the state alone,
/// no parameters to check) at `x`.
fn time_kernel(k: &Kernel, x: &[f64]) -> Result<f64, KernelError> {
    let mut f = vec![0.0; k.n_states()];
    let mut v = vec![0.0; k.nnz()];
    k.rhs_and_jacobian_values(x, &mut f, &mut v)?;
    let once = || {
        let _ = k.rhs_and_jacobian_values(std::hint::black_box(x), &mut f, &mut v);
    };
    Ok(time_per_call(once, 2e-3, 21, 0.6).0)
}

/// The first RHS + Jacobian call (the JIT compiles the tape then).
fn first_call(m: &dyn Model, p: &[f64], x: &[f64]) -> Duration {
    let mut f = vec![0.0; m.n_states()];
    let mut v = vec![0.0; m.jacobian_pattern(p).len()];
    let t = Instant::now();
    m.rhs_and_jacobian_values(p, x, 0.0, &mut f, &mut v);
    t.elapsed()
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The load of the file and everything up to a native RHS + Jacobian at `n`, cold (the first
/// load in this process): each stage's milliseconds.
fn load(path: &Path, n: usize) -> Result<(Arc<Definition>, Value), Box<dyn std::error::Error>> {
    let t = Instant::now();
    let topo = stirling_front::load::load_file(path, files::BASES)?;
    let parsed = t.elapsed();
    let def = Definition::new(topo);
    let assembled = t.elapsed();
    let m = files::jit(def.model(n, Closure::Full)?);
    let taped = t.elapsed();
    let p = m.default_params();
    let x = vec![1.0; m.n_states()];
    first_call(&m, &p, &x);
    let native = t.elapsed();
    let doc = json!({
        "n": n,
        "read_lower_ms": ms(parsed),
        "assemble_differentiate_ms": ms(assembled - parsed),
        "tapes_ms": ms(taped - assembled),
        "jit_rhs_jacobian_ms": ms(native - taped),
        "total_ms": ms(native),
    });
    Ok((def, doc))
}

/// The state, RHS and Jacobian triplets of `m` at its fairness state.
fn values(m: &CompiledModel, p: &[f64], x: &[f64]) -> Value {
    let mut f = vec![0.0; m.n_states()];
    m.rhs(p, x, 0.0, &mut f);
    let jac: Vec<Value> = m
        .jacobian_triplets(p, x, 0.0)
        .into_iter()
        .map(|(r, c, v)| json!([r, c, v]))
        .collect();
    json!({"x": x, "f": f, "jac": jac})
}

/// One `n`: build times and the kernels' seconds per call.
fn row(def: &Arc<Definition>, n: usize) -> Result<Value, Box<dyn std::error::Error>> {
    let t = Instant::now();
    let tape = def.model(n, Closure::Full)?;
    let build = t.elapsed();
    let mac = NSection::new(n, Closure::Full)?;
    let p = mac.default_params();
    let x = fairness_state(&mac, &p);
    let jit = files::jit(def.model(n, Closure::Full)?);
    let jit_compile = first_call(&jit, &p, &x);
    let folded = jit.folded(&p);
    let folded_compile = first_call(&folded, &p, &x);
    let folded_c = files::folded_native(&jit, &p);
    let folded_c_compile = first_call(&folded_c, &p, &x);
    let kernel = folded_c
        .kernel()
        .ok_or("the folded model has no native kernel")?;
    let (mut best, mut k) = ([f64::INFINITY; 4], f64::INFINITY);
    for _ in 0..3 {
        k = k.min(time_kernel(&kernel, &x)?);
        for (b, m) in best
            .iter_mut()
            .zip([&mac as &dyn Model, &jit, &folded, &folded_c])
        {
            *b = b.min(time(m, &p, &x));
        }
    }
    let [a, c, d, e] = best;
    let b = time(&tape, &p, &x);
    let names: Vec<&str> = mac.params().iter().map(|q| q.name).collect();
    let params: serde_json::Map<String, Value> = names
        .iter()
        .zip(&p)
        .map(|(k, v)| (k.to_string(), json!(v)))
        .collect();
    let (rhs_ops, jac_ops) = tape.tape_sizes();
    Ok(json!({
        "n": n, "tape_build_ms": ms(build), "jit_compile_ms": ms(jit_compile),
        "jit_folded_compile_ms": ms(folded_compile),
        "cc_folded_compile_ms": ms(folded_c_compile),
        "tape_ops": {"rhs": rhs_ops, "jac": jac_ops,
                     "rhs_jac": tape.rhs_jacobian_tape(&p).ops.len(),
                     "rhs_jac_folded": folded.rhs_jacobian_tape(&p).ops.len()},
        "macro_ns": a * 1e9, "tape_ns": b * 1e9, "jit_ns": c * 1e9, "jit_folded_ns": d * 1e9,
        "cc_folded_ns": e * 1e9, "cc_folded_over_macro": e / a,
        "kernel_ns": k * 1e9, "kernel_over_macro": k / a,
        "tape_over_macro": b / a, "jit_over_macro": c / a, "jit_folded_over_macro": d / a,
        "params": params, "folded_at_x": values(&folded, &p, &x),
        "cc_folded_at_x": values(&folded_c, &p, &x),
    }))
}

/// The `n`s of `--ns 2,10,...` (2, 10, 100, 1000 without).
fn ns(args: &[String]) -> Result<Vec<usize>, Box<dyn std::error::Error>> {
    match args.iter().position(|a| a == "--ns") {
        None => Ok(vec![2, 10, 100, 1000]),
        Some(i) => {
            let list = args.get(i + 1).ok_or("--ns needs a list, e.g. 2,10,100")?;
            Ok(list
                .split(',')
                .map(|s| s.trim().parse())
                .collect::<Result<_, _>>()?)
        }
    }
}

fn print_table(load: &Value, rows: &[Value]) {
    let f = |r: &Value, k: &str| r[k].as_f64().unwrap_or(f64::NAN);
    println!(
        "nsection.stirling to a native RHS + Jacobian at n = {}: {:.1} ms (read and lower {:.1}, \
         assemble and differentiate {:.1}, tapes {:.1}, JIT {:.1})",
        load["n"],
        f(load, "total_ms"),
        f(load, "read_lower_ms"),
        f(load, "assemble_differentiate_ms"),
        f(load, "tapes_ms"),
        f(load, "jit_rhs_jacobian_ms"),
    );
    println!("RHS + Jacobian values per call (ns):");
    println!(
        "     n    macro     tape      jit  jit fold   cc fold   kernel  tape/mac  jit/mac  \
         fold/mac  cc/mac  kernel/mac  tapes (ms)  jit compile (ms)  cc compile (ms)"
    );
    for r in rows {
        println!(
            "{:>6} {:>8.0} {:>8.0} {:>8.0} {:>9.0} {:>9.0} {:>8.0} {:>9.2} {:>8.2} {:>9.2} {:>7.2} {:>11.2} {:>11.1} {:>17.1} {:>16.1}",
            r["n"],
            f(r, "macro_ns"),
            f(r, "tape_ns"),
            f(r, "jit_ns"),
            f(r, "jit_folded_ns"),
            f(r, "cc_folded_ns"),
            f(r, "kernel_ns"),
            f(r, "tape_over_macro"),
            f(r, "jit_over_macro"),
            f(r, "jit_folded_over_macro"),
            f(r, "cc_folded_over_macro"),
            f(r, "kernel_over_macro"),
            f(r, "tape_build_ms"),
            f(r, "jit_compile_ms"),
            f(r, "cc_folded_compile_ms")
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let json = args.iter().any(|a| a == "--json");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/nsection.stirling");
    let (def, load) = load(&path, 10)?;
    let rows = ns(&args)?
        .into_iter()
        .map(|n| row(&def, n))
        .collect::<Result<Vec<_>, _>>()?;
    if json {
        let out = json!({"load": load, "rhs_jacobian": rows});
        println!("{}", serde_json::to_string(&out)?);
    } else {
        print_table(&load, &rows);
    }
    Ok(())
}
