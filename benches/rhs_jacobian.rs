//! RHS and analytic Jacobian of `nsection` at n = 10, 100, 1000, against a
//! finite-difference Jacobian as the in-process baseline, and of `nsection` with a
//! regenerator matrix of finite heat capacity (`wall matrix[n]`, section `j` behind
//! `regen[j]`, axial conduction to the heater and cooler ends): `n` more states, a
//! tridiagonal wall block. Cost must grow linearly in n, with and without the matrix.
//!
//! Run: `cargo bench --bench rhs_jacobian` (short: `-- --warm-up-time 1 --measurement-time 3`).

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use stirling::dsl::{Closure, JacSink, Model};
use stirling::models::family::NSection;
use stirling::stirling_model;

#[path = "../examples/support/fairness.rs"]
mod fairness;
use fairness::fairness_state;

stirling_model! {
    /// `nsection` with a regenerator matrix of heat capacity `Cm` (a wall array) conducting
    /// axially to the fixed heater and cooler temperatures.
    pub model NSectionMatrix extends stirling::models::nsection_engine {
        name "nsection_matrix";
        params {
            /// heat capacity of the whole regenerator matrix
            Cm: 25.0 "J/K",
            /// axial conductance of the whole matrix
            Gm: 0.03 "W/K",
        }
        modify cv regen { port wall { h: hr, area: Awr / n, wall: matrix[j] } }
        wall matrix[n] { capacity: Cm / n, rest: Th - (j + 0.5) * (Th - Tk) / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
    }
}

/// Forward differences, one RHS per column: the baseline an analytic Jacobian replaces.
fn fd_jacobian(
    m: &dyn Model,
    p: &[f64],
    x: &[f64],
    f0: &[f64],
    out: &mut Vec<(usize, usize, f64)>,
) {
    let n = x.len();
    let mut xp = x.to_vec();
    let mut f = vec![0.0; n];
    out.clear();
    for c in 0..n {
        let h = 1e-7 * x[c].abs().max(1e-6);
        xp[c] = x[c] + h;
        m.rhs(p, &xp, 0.0, &mut f);
        xp[c] = x[c];
        for r in 0..n {
            let d = (f[r] - f0[r]) / h;
            if d != 0.0 {
                out.push((r, c, d));
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("nsection_full");
    g.sample_size(20);
    for n in [10usize, 100, 1000] {
        let m = NSection::new(n, Closure::Full).expect("n >= 1");
        let p = m.default_params();
        let x = fairness_state(&m, &p);
        rhs_and_jacobian(&mut g, "", &m, &p, &x, n);
        if n <= 100 {
            let mut f0 = vec![0.0; x.len()];
            m.rhs(&p, &x, 0.0, &mut f0);
            let mut trip = Vec::with_capacity(16 * x.len());
            g.bench_with_input(BenchmarkId::new("jacobian_fd", n), &n, |b, _| {
                b.iter(|| fd_jacobian(&m, black_box(&p), black_box(&x), &f0, &mut trip))
            });
        }
        let m = NSectionMatrix::new(n, Closure::Full).expect("n >= 1");
        let p = m.default_params();
        let x = fairness_state(&m, &p);
        rhs_and_jacobian(&mut g, "_matrix", &m, &p, &x, n);
    }
    g.finish();
}

/// `rhs{tag}` and `jacobian_analytic{tag}` of `m` at `x`.
fn rhs_and_jacobian(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    tag: &str,
    m: &dyn Model,
    p: &[f64],
    x: &[f64],
    n: usize,
) {
    let mut out = vec![0.0; x.len()];
    let mut trip = Vec::with_capacity(16 * x.len());
    g.bench_with_input(BenchmarkId::new(format!("rhs{tag}"), n), &n, |b, _| {
        b.iter(|| m.rhs(black_box(p), black_box(x), 0.0, &mut out))
    });
    g.bench_with_input(
        BenchmarkId::new(format!("jacobian_analytic{tag}"), n),
        &n,
        |b, _| {
            b.iter(|| {
                trip.clear();
                m.jacobian(
                    black_box(p),
                    black_box(x),
                    0.0,
                    &mut JacSink::Triplets(&mut trip),
                )
            })
        },
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
