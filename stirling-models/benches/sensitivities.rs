//! The forward sensitivities a fit evaluates, staggered against augmented (same process):
//! `nsection` n = 2 (default engine, displacer displaced 2 mm), every state free, 0.2 s,
//! sampled at 2 kHz, with 8 columns (the mechanical and heat-transfer parameters and two
//! initial states). Staggered: `Driven::integrate` (states by Newton on `nz x nz`, every
//! column corrected with the same factorization, `crate::sim::sens`); augmented: the
//! `[z, S]` system of `(1 + k) nz` states with the block LU, as before.

use criterion::{criterion_group, criterion_main, Criterion};
use stirling_dsl::Closure;
use stirling_models::fit::sensitivity::{Column, Driven};
use stirling_models::sim::{integrate, state_scale, Hooks, LinearSolverKind, SimOptions};

fn bench(c: &mut Criterion) {
    let model = stirling_models::build("nsection", Some(2), Closure::Full).unwrap();
    let p = model.default_params();
    let n = model.n_states();
    let mut z0 = vec![0.0; n];
    model.equilibrium_guess(&p, &mut z0);
    z0[0] += 2e-3;
    let mut columns: Vec<Column> = ["kd", "kp", "bd", "bp", "hh", "hk"]
        .iter()
        .map(|q| Column::Param {
            index: model.param_index(q).unwrap(),
            scale: p[model.param_index(q).unwrap()],
        })
        .collect();
    columns.push(Column::Initial {
        pos: 0,
        scale: 1e-3,
    });
    columns.push(Column::Initial {
        pos: 1,
        scale: 1e-2,
    });
    let sys = Driven {
        model: model.as_ref(),
        p: p.clone(),
        base: z0.clone(),
        free: (0..n).collect(),
        given: Vec::new(),
        signals: Vec::new(),
        columns,
        zscale: state_scale(model.as_ref(), &p),
    };
    let samples: Vec<f64> = (0..=400).map(|k| k as f64 * 5e-4).collect();
    let opts = SimOptions::default();
    let augmented = SimOptions {
        linear_solver: LinearSolverKind::Sparse,
        ..opts
    };
    let mut g = c.benchmark_group("sensitivities_nsection2_0p2s");
    g.sample_size(10);
    g.bench_function("staggered", |b| {
        b.iter(|| sys.integrate(&z0, 0.2, &samples, &opts).unwrap())
    });
    g.bench_function("augmented", |b| {
        b.iter(|| {
            let x0 = sys.initial(&z0);
            integrate(&sys, &x0, 0.2, &samples, &augmented, Hooks::default()).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
