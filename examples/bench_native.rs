//! Native timings of the generated `nsection` model, for the comparison harness in `bench/`.
//!
//! Run: `cargo run --release --example bench_native -- --n 10 --json`
//!
//! Options: `--n N` (regenerator sections, default 10), `--json` (machine-readable output; the
//! default is a short human summary), `--no-sim` (skip the simulated second), `--no-poles`
//! (skip the linearization), `--t-end T` (simulated time, default 1 s).
//!
//! What is measured (all in this process, wall clock, median over repeats; fast calls are timed
//! in batches so the clock resolution does not matter):
//! - `rhs`: one right-hand side call;
//! - `jac`: one analytic Jacobian, its values alone in the fixed order of
//!   `Model::jacobian_pattern` (`Model::jacobian_values`: the form a sparse solver refills, and
//!   the form of CasADi's generated code); `jac_triplets`: the same into triplets (pattern and
//!   values; the buffer is reused);
//! - `rhs_jac`: the right-hand side and the Jacobian values in one call
//!   (`Model::rhs_and_jacobian_values`, which shares their common values); `rhs_jac_triplets`:
//!   the same into triplets (`Model::rhs_and_jacobian`);
//! - `jac_fd`: one forward-difference Jacobian (n_states + 1 RHS calls) into triplets;
//! - `sim`: one second of engine time from the rest state with the displacer moved by 5 mm
//!   (as `stirling simulate` does), with the default stiff BDF of `stirling_models::sim`
//!   (rtol = atol = 1e-7 relative to each state's scale); solver counters are reported;
//! - `poles`: `linear::dynamic_poles`: Newton equilibrium, Jacobian, inventory reduction and
//!   all eigenvalues.
//!
//! The JSON also carries the parameters (names and values), the fairness state `x`, `f(x)` and
//! the Jacobian triplets at `x`, so other implementations can be checked against this one.

use std::hint::black_box;
use std::time::Instant;

use serde_json::json;
use stirling::dsl::{Closure, JacSink, Model};
use stirling::models::family::NSection;
use stirling::models::linear::{dynamic_poles, NewtonOptions};
use stirling::models::sim::{integrate, simulate, state_scale, Hooks, ModelSystem, SimOptions};

#[path = "support/fairness.rs"]
mod fairness;
use fairness::{fairness_state, median, time_per_call};

/// Forward differences, one RHS per column, nonzeros kept as triplets.
fn fd_jacobian(
    m: &dyn Model,
    p: &[f64],
    x: &[f64],
    base: &mut [f64],
    xp: &mut [f64],
    f: &mut [f64],
    out: &mut Vec<(usize, usize, f64)>,
) {
    let n = x.len();
    out.clear();
    m.rhs(p, x, 0.0, base); // f(x) is part of the cost of a finite-difference Jacobian
    for c in 0..n {
        let h = 1e-7 * x[c].abs().max(1e-6);
        xp[c] = x[c] + h;
        m.rhs(p, xp, 0.0, f);
        xp[c] = x[c];
        for r in 0..n {
            let d = (f[r] - base[r]) / h;
            if d != 0.0 {
                out.push((r, c, d));
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut n = 10usize;
    let mut as_json = false;
    let mut do_sim = true;
    let mut do_poles = true;
    let mut t_end = 1.0f64;
    let mut i = 1;
    while i < args.len() {
        match args[i].as_str() {
            "--n" => {
                i += 1;
                n = args[i].parse().expect("--n N");
            }
            "--t-end" => {
                i += 1;
                t_end = args[i].parse().expect("--t-end T");
            }
            "--json" => as_json = true,
            "--no-sim" => do_sim = false,
            "--no-poles" => do_poles = false,
            "-h" | "--help" => {
                eprintln!(
                    "usage: bench_native [--n N] [--json] [--no-sim] [--no-poles] [--t-end T]"
                );
                return;
            }
            other => panic!("unknown argument `{other}`"),
        }
        i += 1;
    }

    let m = NSection::new(n, Closure::Full).expect("n >= 1");
    let p = m.default_params();
    let ns = m.n_states();
    let x = fairness_state(&m, &p);
    let mut f = vec![0.0; ns];
    m.rhs(&p, &x, 0.0, &mut f);
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(16 * ns);
    m.jacobian(&p, &x, 0.0, &mut JacSink::Triplets(&mut trip));
    let jac_at_x = trip.clone();

    // --- RHS
    let mut out = vec![0.0; ns];
    let (t_rhs, n_rhs) = time_per_call(
        || m.rhs(black_box(&p), black_box(&x), 0.0, black_box(&mut out)),
        2e-3,
        51,
        2.0,
    );
    // --- analytic Jacobian: values alone in the pattern's order (the sparse solvers' format,
    // and CasADi's), then as triplets (pattern and values)
    let mut vals = vec![0.0; m.jacobian_pattern(&p).len()];
    let (t_jac, n_jac) = time_per_call(
        || m.jacobian_values(black_box(&p), black_box(&x), 0.0, black_box(&mut vals)),
        2e-3,
        51,
        2.0,
    );
    let (t_jac_trip, _) = time_per_call(
        || {
            trip.clear();
            m.jacobian(
                black_box(&p),
                black_box(&x),
                0.0,
                &mut JacSink::Triplets(&mut trip),
            );
            black_box(&trip);
        },
        2e-3,
        51,
        2.0,
    );
    // --- right-hand side and Jacobian in one call (`Model::rhs_and_jacobian_values`,
    // `Model::rhs_and_jacobian` into triplets)
    let (t_rhs_jac, _) = time_per_call(
        || {
            m.rhs_and_jacobian_values(
                black_box(&p),
                black_box(&x),
                0.0,
                black_box(&mut out),
                black_box(&mut vals),
            )
        },
        2e-3,
        51,
        2.0,
    );
    let (t_rhs_jac_trip, _) = time_per_call(
        || {
            trip.clear();
            m.rhs_and_jacobian(
                black_box(&p),
                black_box(&x),
                0.0,
                black_box(&mut out),
                &mut JacSink::Triplets(&mut trip),
            );
            black_box(&trip);
        },
        2e-3,
        51,
        2.0,
    );
    // --- analytic Jacobian, dense column-major (what the dense BDF uses)
    let mut dense = vec![0.0; ns * ns];
    let (t_jac_dense, _) = time_per_call(
        || {
            dense.iter_mut().for_each(|v| *v = 0.0);
            m.jacobian(
                black_box(&p),
                black_box(&x),
                0.0,
                &mut JacSink::Dense {
                    data: &mut dense,
                    nrows: ns,
                },
            );
            black_box(&dense);
        },
        2e-3,
        21,
        2.0,
    );
    // --- finite-difference Jacobian
    let mut xp = x.clone();
    let mut ff = vec![0.0; ns];
    let mut fbase = vec![0.0; ns];
    let mut fd_trip = Vec::with_capacity(16 * ns);
    let (t_fd, _) = time_per_call(
        || {
            fd_jacobian(
                &m,
                black_box(&p),
                black_box(&x),
                &mut fbase,
                &mut xp,
                &mut ff,
                &mut fd_trip,
            )
        },
        2e-3,
        21,
        3.0,
    );
    // FD accuracy against the analytic Jacobian (relative to the column scale), for the record
    let fd_err = {
        let mut a = vec![0.0; ns * ns];
        for &(r, c, v) in &jac_at_x {
            a[r + c * ns] += v;
        }
        let mut d = vec![0.0; ns * ns];
        for &(r, c, v) in &fd_trip {
            d[r + c * ns] += v;
        }
        let mut worst: f64 = 0.0;
        for c in 0..ns {
            let col_max = (0..ns)
                .map(|r| a[r + c * ns].abs())
                .fold(0.0, f64::max)
                .max(1e-300);
            for r in 0..ns {
                worst = worst.max((a[r + c * ns] - d[r + c * ns]).abs() / col_max);
            }
        }
        worst
    };

    // --- one simulated second
    let mut x0 = vec![0.0; ns];
    m.equilibrium_guess(&p, &mut x0);
    x0[0] += 5e-3;
    let scale = state_scale(&m, &p);
    let opts = SimOptions::default();
    let sim = if do_sim {
        let samples = [t_end];
        let mut times = Vec::new();
        let mut last = None;
        let started = Instant::now();
        // at least 3 runs (median), more while the total stays under ~3 s, at most 7
        while times.len() < 7 && (times.len() < 3 || started.elapsed().as_secs_f64() < 3.0) {
            let t = Instant::now();
            let r = simulate(&m, &p, &x0, t_end, &samples, &opts);
            times.push(t.elapsed().as_secs_f64());
            let failed = r.is_err();
            last = Some(r);
            if failed || (times.len() == 1 && times[0] > 20.0) {
                break;
            }
        }
        let runs = times.len();
        let med = median(&mut times);
        Some(match last.unwrap() {
            Ok(tr) => json!({
                "ok": true, "t_end": t_end, "seconds": med, "runs": runs,
                "steps": tr.stats.steps, "rhs_calls": tr.stats.rhs_calls,
                "jacobian_calls": tr.stats.jacobian_calls, "lu_factorizations": tr.stats.lu_factorizations,
                "error_test_failures": tr.stats.error_test_failures, "newton_failures": tr.stats.newton_failures,
                "newton_iterations": tr.stats.newton_iterations,
                "x_end": tr.x_end,
            }),
            Err(e) => json!({"ok": false, "error": e.to_string(), "seconds": med, "runs": runs}),
        })
    } else {
        None
    };

    // --- the same run without the per-step nonphysical-state check (to size its overhead)
    let sim_nocheck = if do_sim {
        let mut times = Vec::new();
        let mut steps = 0;
        for _ in 0..3 {
            let t = Instant::now();
            let r = integrate(
                &ModelSystem { model: &m, p: &p },
                &x0,
                t_end,
                &[t_end],
                &opts,
                Hooks::default(),
            );
            times.push(t.elapsed().as_secs_f64());
            match r {
                Ok(tr) => steps = tr.stats.steps,
                Err(_) => break,
            }
            if times[0] > 20.0 {
                break;
            }
        }
        Some(json!({"seconds": median(&mut times), "steps": steps}))
    } else {
        None
    };

    // --- linearization with all poles
    let poles = if do_poles {
        let newton = NewtonOptions::default();
        let mut times = Vec::new();
        let mut last = None;
        let started = Instant::now();
        while times.len() < 7 && (times.len() < 3 || started.elapsed().as_secs_f64() < 2.0) {
            let t = Instant::now();
            let r = dynamic_poles(&m, &p, &newton);
            times.push(t.elapsed().as_secs_f64());
            last = Some(r);
            if times.len() == 1 && times[0] > 20.0 {
                break;
            }
        }
        let runs = times.len();
        let med = median(&mut times);
        Some(match last.unwrap() {
            Ok(d) => {
                let mut top: Vec<_> = d.poles.iter().map(|q| (q.re, q.im)).collect();
                top.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
                json!({
                    "ok": true, "seconds": med, "runs": runs, "count": d.poles.len(),
                    "newton_iterations": d.equilibrium.iterations,
                    "rightmost": top.iter().take(4).map(|&(re, im)| [re, im]).collect::<Vec<_>>(),
                })
            }
            Err(e) => json!({"ok": false, "error": e.to_string(), "seconds": med, "runs": runs}),
        })
    } else {
        None
    };

    if as_json {
        let names: Vec<&str> = m.params().iter().map(|q| q.name).collect();
        let doc = json!({
            "model": "nsection", "n": n, "closure": "full", "n_states": ns,
            "params": names.iter().zip(&p).map(|(k, v)| (k.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
            "state_names": m.state_names(),
            "scale": scale,
            "x": x, "f": f,
            "jac": jac_at_x.iter().map(|&(r, c, v)| json!([r, c, v])).collect::<Vec<_>>(),
            "x0_sim": x0,
            "rtol": opts.rtol, "atol": opts.atol,
            "timings": {
                "rhs": t_rhs, "rhs_calls_timed": n_rhs,
                "jac": t_jac, "jac_calls_timed": n_jac, "jac_nnz": jac_at_x.len(),
                "rhs_jac": t_rhs_jac,
                "jac_triplets": t_jac_trip, "rhs_jac_triplets": t_rhs_jac_trip,
                "jac_dense": t_jac_dense,
                "jac_fd": t_fd, "jac_fd_max_rel_err": fd_err,
            },
            "sim": sim, "sim_nocheck": sim_nocheck, "poles": poles,
        });
        println!("{}", serde_json::to_string(&doc).unwrap());
    } else {
        println!("nsection n = {n} (full, {ns} states)");
        println!("  rhs          {:>12.3} us", t_rhs * 1e6);
        println!(
            "  jac analytic {:>12.3} us ({} nonzeros)",
            t_jac * 1e6,
            jac_at_x.len()
        );
        println!("  jac triplets {:>12.3} us", t_jac_trip * 1e6);
        println!("  rhs + jac    {:>12.3} us (one call)", t_rhs_jac * 1e6);
        println!(
            "  rhs + jac    {:>12.3} us (one call, triplets)",
            t_rhs_jac_trip * 1e6
        );
        println!("  jac dense    {:>12.3} us", t_jac_dense * 1e6);
        println!(
            "  jac FD       {:>12.3} us (x{:.1}, max rel err {:.1e})",
            t_fd * 1e6,
            t_fd / t_jac,
            fd_err
        );
        if let Some(s) = &sim {
            println!("  sim {t_end} s     {}", s);
        }
        if let Some(q) = &poles {
            println!("  poles        {}", q);
        }
    }
}
