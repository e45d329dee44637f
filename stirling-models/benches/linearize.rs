//! Time to linearize `nsection` (full closure, default engine) and compute its poles:
//! - `linearize_nsection_poles`: the dense route (equilibrium, dense analytic Jacobian,
//!   inventory reduction and all balanced eigenvalues) at n = 10, 100, 1000 (28, 208, 2008
//!   states);
//! - `dominant_poles`: the sparse route (sparse Newton, the 8 dominant poles by shift-invert
//!   Arnoldi) at n = 1000 and 10,000 (2008 and 20,008 states), in the same run as the dense one
//!   at n = 1000 so that the ratio is measured on one machine state.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use stirling_dsl::Closure;
use stirling_models::linear::{dynamic_poles_with, NewtonOptions, PoleRequest};

fn run(c: &mut Criterion, group: &str, ns: &[usize], request: PoleRequest) {
    let mut group = c.benchmark_group(group);
    for &n in ns {
        let model = stirling_models::build("nsection", Some(n), Closure::Full).unwrap();
        let p = model.default_params();
        if n >= 1000 {
            group.sample_size(10);
        }
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| {
                dynamic_poles_with(model.as_ref(), &p, &NewtonOptions::default(), request)
                    .unwrap()
                    .poles
                    .len()
            })
        });
    }
    group.finish();
}

fn linearize(c: &mut Criterion) {
    run(
        c,
        "linearize_nsection_poles",
        &[10, 100, 1000],
        PoleRequest::All,
    );
    run(
        c,
        "dominant_poles",
        &[1000, 10_000],
        PoleRequest::Dominant(8),
    );
}

criterion_group!(benches, linearize);
criterion_main!(benches);
