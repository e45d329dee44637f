//! RHS and analytic Jacobian of `nsection` at n = 10, 100, 1000, against a
//! finite-difference Jacobian as the in-process baseline. Cost must grow linearly in n.
//!
//! Run: `cargo bench --bench rhs_jacobian`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion};
use stirling::dsl::{Closure, JacSink, Model};
use stirling::models::family::NSection;

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
        let x = state(&m, &p);
        let mut out = vec![0.0; x.len()];
        let mut trip = Vec::with_capacity(16 * x.len());
        g.bench_with_input(BenchmarkId::new("rhs", n), &n, |b, _| {
            b.iter(|| m.rhs(black_box(&p), black_box(&x), 0.0, &mut out))
        });
        g.bench_with_input(BenchmarkId::new("jacobian_analytic", n), &n, |b, _| {
            b.iter(|| {
                trip.clear();
                m.jacobian(
                    black_box(&p),
                    black_box(&x),
                    0.0,
                    &mut JacSink::Triplets(&mut trip),
                )
            })
        });
        if n <= 100 {
            let mut f0 = vec![0.0; x.len()];
            m.rhs(&p, &x, 0.0, &mut f0);
            g.bench_with_input(BenchmarkId::new("jacobian_fd", n), &n, |b, _| {
                b.iter(|| fd_jacobian(&m, black_box(&p), black_box(&x), &f0, &mut trip))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
