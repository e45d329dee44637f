//! Time to linearize `nsection` (full closure, default engine) and compute all its poles:
//! equilibrium, dense analytic Jacobian, inventory reduction and the balanced eigenvalues,
//! at n = 10, 100, 1000 (28, 208, 2008 states).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use stirling_dsl::Closure;
use stirling_models::linear::{dynamic_poles, NewtonOptions};

fn linearize(c: &mut Criterion) {
    let mut group = c.benchmark_group("linearize_nsection_poles");
    for n in [10usize, 100, 1000] {
        let model = stirling_models::build("nsection", Some(n), Closure::Full).unwrap();
        let p = model.default_params();
        if n >= 1000 {
            group.sample_size(10);
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                dynamic_poles(model.as_ref(), &p, &NewtonOptions::default())
                    .unwrap()
                    .poles
                    .len()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, linearize);
criterion_main!(benches);
