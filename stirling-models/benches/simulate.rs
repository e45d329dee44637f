//! One simulated second of `nsection` (full closure, default engine, displacer
//! displaced 5 mm) at n = 2, 10, 100; n = 1000 with `STIRLING_BENCH_N1000=1`
//! (dense LU on 2008 states: minutes). Prints steps and Jacobian calls once per n.

use criterion::{criterion_group, criterion_main, Criterion};
use stirling_dsl::{Closure, Model};
use stirling_models::family::NSection;
use stirling_models::sim::{self, SimOptions};

fn one_second(model: &dyn Model, p: &[f64]) -> sim::Trajectory {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    x0[0] = 5e-3;
    sim::simulate(model, p, &x0, 1.0, &[1.0], &SimOptions::default()).expect("the default engine runs")
}

fn bench(c: &mut Criterion) {
    let mut ns = vec![2, 10, 100];
    if std::env::var_os("STIRLING_BENCH_N1000").is_some() {
        ns.push(1000);
    }
    let mut g = c.benchmark_group("simulate_1s");
    g.sample_size(10);
    for n in ns {
        let model = NSection::new(n, Closure::Full).unwrap();
        let p = model.default_params();
        let t0 = std::time::Instant::now();
        let tr = one_second(&model, &p);
        eprintln!(
            "nsection n = {n} ({} states): {:?} per simulated second; {} steps, {} RHS, {} Jacobian calls, {} LU",
            model.n_states(),
            t0.elapsed(),
            tr.stats.steps,
            tr.stats.rhs_calls,
            tr.stats.jacobian_calls,
            tr.stats.lu_factorizations
        );
        if n <= 100 {
            g.bench_function(format!("nsection_{n}"), |b| b.iter(|| one_second(&model, &p)));
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
