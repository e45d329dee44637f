//! Engines from files, timed: the load and compile time of `examples/engines/nsection.stirling`
//! (read, compose, check, lower, assemble, differentiate, lay out the tapes at `n`), and the
//! right-hand side with the sparse Jacobian (`Model::rhs_and_jacobian_values`) of the macro's
//! `nsection`, the file's tape (interpreted), the tape compiled to native code by the JIT
//! (`stirling-jit`, with its compile time: the first call) and the JIT with the parameters
//! folded in, at n = 2, 10, 100, 1000.
//!
//! Run: `cargo run --release --example files_speed` (`--json` for the numbers only).

use std::path::Path;
use std::time::{Duration, Instant};

use stirling::dsl::compiled::Definition;
use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::files;

/// A state near the equilibrium with the bodies displaced (every branch of the upwind
/// switches taken somewhere).
fn state(m: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    x[0] = 3e-3;
    x[1] = 0.2;
    x[2] = -2e-3;
    x[3] = -0.1;
    for (i, s) in m.states().iter().enumerate() {
        if s.unit == "Pa" {
            x[i] *= 1.0 + 1e-3 * ((i % 7) as f64);
        }
    }
    x
}

/// Nanoseconds per call of RHS + Jacobian values, the best of five runs of ~0.2 s.
fn time(m: &dyn Model, p: &[f64]) -> f64 {
    let x = state(m, p);
    let mut f = vec![0.0; m.n_states()];
    let mut v = vec![0.0; m.jacobian_pattern(p).len()];
    let mut once = || m.rhs_and_jacobian_values(p, &x, 0.0, &mut f, &mut v);
    let start = Instant::now();
    let mut calls = 0u64;
    while start.elapsed() < Duration::from_millis(50) {
        once();
        calls += 1;
    }
    let reps = calls.max(1) * 4;
    (0..5)
        .map(|_| {
            let t = Instant::now();
            for _ in 0..reps {
                once();
            }
            t.elapsed().as_nanos() as f64 / reps as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// The first RHS + Jacobian call: the JIT compiles the tape then.
fn first_call(m: &dyn Model, p: &[f64]) -> Duration {
    let x = state(m, p);
    let mut f = vec![0.0; m.n_states()];
    let mut v = vec![0.0; m.jacobian_pattern(p).len()];
    let t = Instant::now();
    m.rhs_and_jacobian_values(p, &x, 0.0, &mut f, &mut v);
    t.elapsed()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let json = std::env::args().any(|a| a == "--json");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/engines/nsection.stirling");
    // cold: the first load in this process
    let t = Instant::now();
    let topo = stirling_front::load::load_file(&path, stirling::models::files::BASES)?;
    let parsed = t.elapsed();
    let def = Definition::new(topo);
    let assembled = t.elapsed();
    let m10 = def.model(10, Closure::Full)?;
    let compiled = t.elapsed();
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mut rows = Vec::new();
    for n in [2usize, 10, 100, 1000] {
        let t = Instant::now();
        let tape = def.model(n, Closure::Full)?;
        let build = t.elapsed();
        let mac = NSection::new(n, Closure::Full)?;
        let p = mac.default_params();
        let jit = files::jit(def.model(n, Closure::Full)?);
        let jit_compile = first_call(&jit, &p);
        let folded = jit.folded(&p);
        let folded_compile = first_call(&folded, &p);
        let (a, b) = (time(&mac, &p), time(&tape, &p));
        let (c, d) = (time(&jit, &p), time(&folded, &p));
        rows.push(serde_json::json!({
            "n": n, "tape_build_ms": ms(build), "jit_compile_ms": ms(jit_compile),
            "jit_folded_compile_ms": ms(folded_compile),
            "macro_ns": a, "tape_ns": b, "jit_ns": c, "jit_folded_ns": d,
            "tape_over_macro": b / a, "jit_over_macro": c / a, "jit_folded_over_macro": d / a,
        }));
    }
    let _ = m10;
    let out = serde_json::json!({
        "load_ms": ms(parsed), "assemble_ms": ms(assembled - parsed),
        "compile_n10_ms": ms(compiled - assembled), "total_n10_ms": ms(compiled), "rhs_jacobian": rows,
    });
    if json {
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!(
        "nsection.stirling: read and lowered {:.1} ms, assembled and differentiated {:.1} ms, \
         tapes at n = 10 {:.1} ms: {:.1} ms in all",
        ms(parsed),
        ms(assembled - parsed),
        ms(compiled - assembled),
        ms(compiled)
    );
    println!("RHS + Jacobian values per call (ns):");
    println!(
        "     n    macro     tape      jit  jit fold  tape/mac  jit/mac  fold/mac  \
         tapes (ms)  jit compile (ms)"
    );
    for r in &rows {
        let f = |k: &str| r[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "{:>6} {:>8.0} {:>8.0} {:>8.0} {:>9.0} {:>9.2} {:>8.2} {:>9.2} {:>11.1} {:>17.1}",
            r["n"],
            f("macro_ns"),
            f("tape_ns"),
            f("jit_ns"),
            f("jit_folded_ns"),
            f("tape_over_macro"),
            f("jit_over_macro"),
            f("jit_folded_over_macro"),
            f("tape_build_ms"),
            f("jit_compile_ms")
        );
    }
    Ok(())
}
