//! The sparse (faer) and dense (nalgebra) linear algebra give the same run, and
//! the Radau IIA monodromy agrees with the variational-system reference.

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::sim::{self, LinearSolverKind, MonodromyMethod, SimOptions};

fn start(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    x[0] = 5e-3;
    x
}

#[test]
fn nsection3_sparse_and_dense_agree() {
    let model = NSection::new(3, Closure::Full).unwrap();
    let p = model.default_params();
    let x0 = start(&model, &p);
    let scale = sim::state_scale(&model, &p);
    let samples = sim::uniform_samples(0.05, 50);
    let run = |kind| {
        let opts = SimOptions {
            rtol: 1e-10,
            atol: 1e-10,
            linear_solver: kind,
            ..SimOptions::default()
        };
        sim::simulate(&model, &p, &x0, 0.05, &samples, &opts).unwrap()
    };
    let (d, s) = (run(LinearSolverKind::Dense), run(LinearSolverKind::Sparse));
    assert_eq!(d.x.len(), s.x.len());
    let mut worst = 0.0f64;
    for (a, b) in d.x.iter().zip(&s.x) {
        for ((u, v), w) in a.iter().zip(b).zip(&scale) {
            worst = worst.max((u - v).abs() / w);
        }
    }
    eprintln!(
        "max scaled difference {worst:.3e}; dense {:?}, sparse {:?}",
        d.stats, s.stats
    );
    assert!(worst < 1e-6, "dense and sparse runs differ by {worst:e}");
}

#[test]
fn nsection2_radau_monodromy_matches_variational() {
    let model = NSection::new(2, Closure::Full).unwrap();
    let p = model.default_params();
    let n = model.n_states();
    let x0 = start(&model, &p);
    let opts = SimOptions {
        rtol: 1e-10,
        atol: 1e-10,
        ..SimOptions::default()
    };
    let t = 0.07;
    let (xr, mr, _) =
        sim::flow_with_monodromy_by(&model, &p, &x0, t, &opts, MonodromyMethod::default()).unwrap();
    let (xv, mv, _) =
        sim::flow_with_monodromy_by(&model, &p, &x0, t, &opts, MonodromyMethod::Variational)
            .unwrap();
    let scale = sim::state_scale(&model, &p);
    let dx = xr
        .iter()
        .zip(&xv)
        .zip(&scale)
        .map(|((a, b), s)| (a - b).abs() / s)
        .fold(0.0, f64::max);
    // scaled monodromy entries: d x_i / d x0_j * s_j / s_i
    let mut dm = 0.0f64;
    for j in 0..n {
        for i in 0..n {
            let k = i + j * n;
            dm = dm.max((mr[k] - mv[k]).abs() * scale[j] / scale[i]);
        }
    }
    eprintln!("state difference {dx:.2e}, scaled monodromy difference {dm:.2e}");
    assert!(dx < 1e-7);
    assert!(
        dm < 1e-5,
        "Radau IIA and variational monodromy differ by {dm:e}"
    );
    // the same with the sparse stage LU
    let sp = SimOptions {
        linear_solver: LinearSolverKind::Sparse,
        ..opts
    };
    let (_, ms, _) =
        sim::flow_with_monodromy_by(&model, &p, &x0, t, &sp, MonodromyMethod::default()).unwrap();
    let ds = mr
        .iter()
        .zip(&ms)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / mr.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(ds < 1e-6, "sparse and dense stage LU differ by {ds:e}");
}
