//! One simulated second of `nsection` (full closure, default engine, displacer
//! displaced 5 mm): dense LU against sparse LU in the same process at n = 2, 10,
//! 100 (criterion), sparse only at n = 1000 (one timed run; skip it with
//! `STIRLING_BENCH_SKIP_N1000=1`). Prints steps and Jacobian calls once per run.

use criterion::{criterion_group, criterion_main, Criterion};
use stirling_dsl::{Closure, Model};
use stirling_models::family::NSection;
use stirling_models::sim::{self, LinearSolverKind, SimOptions};

fn one_second(model: &dyn Model, p: &[f64], kind: LinearSolverKind) -> sim::Trajectory {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    x0[0] = 5e-3;
    let opts = SimOptions {
        linear_solver: kind,
        ..SimOptions::default()
    };
    sim::simulate(model, p, &x0, 1.0, &[1.0], &opts).expect("the default engine runs")
}

fn report(n: usize, model: &dyn Model, p: &[f64], kind: LinearSolverKind) -> sim::Trajectory {
    let t0 = std::time::Instant::now();
    let tr = one_second(model, p, kind);
    eprintln!(
        "nsection n = {n} ({} states), {kind:?}: {:?} per simulated second; {} steps, {} RHS, {} Jacobian calls, {} LU",
        model.n_states(),
        t0.elapsed(),
        tr.stats.steps,
        tr.stats.rhs_calls,
        tr.stats.jacobian_calls,
        tr.stats.lu_factorizations
    );
    tr
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("simulate_1s");
    g.sample_size(10);
    for n in [2, 10, 100] {
        let model = NSection::new(n, Closure::Full).unwrap();
        let p = model.default_params();
        let d = report(n, &model, &p, LinearSolverKind::Dense);
        let s = report(n, &model, &p, LinearSolverKind::Sparse);
        let diff = d
            .x_end
            .iter()
            .zip(&s.x_end)
            .zip(&sim::state_scale(&model, &p))
            .map(|((a, b), s)| (a - b).abs() / s)
            .fold(0.0, f64::max);
        eprintln!(
            "nsection n = {n}: dense vs sparse final state, max scaled difference {diff:.2e}"
        );
        g.bench_function(format!("nsection_{n}_dense"), |b| {
            b.iter(|| one_second(&model, &p, LinearSolverKind::Dense))
        });
        g.bench_function(format!("nsection_{n}_sparse"), |b| {
            b.iter(|| one_second(&model, &p, LinearSolverKind::Sparse))
        });
    }
    if std::env::var_os("STIRLING_BENCH_SKIP_N1000").is_none() {
        let model = NSection::new(1000, Closure::Full).unwrap();
        let p = model.default_params();
        report(1000, &model, &p, LinearSolverKind::Sparse);
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
