//! The BDF integrator agrees with an independent method: a fixed-step two-stage
//! Radau IIA scheme (order 3, L-stable) with Newton on the analytic Jacobian,
//! written only for this test, on `cv1` and `nsection 1` over a short window.

use stirling::dsl::{Closure, Model};
use stirling::models::family::{Cv1, NSection};
use stirling::models::sim::{self, SimOptions};

/// Solve `a x = b` (row-major `a`, `n x n`) by Gaussian elimination with partial pivoting.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Vec<f64> {
    for c in 0..n {
        let piv = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap();
        for k in 0..n {
            a.swap(c * n + k, piv * n + k);
        }
        b.swap(c, piv);
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] -= f * a[c * n + k];
            }
            b[r] -= f * b[c];
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| a[c * n + k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c * n + c];
    }
    b
}

/// One Radau IIA (s = 2) step: stages `Z = [z1, z2]`, Newton with the Jacobian at `y`.
fn radau_step(model: &dyn Model, p: &[f64], y: &[f64], t: f64, h: f64) -> Vec<f64> {
    const A: [[f64; 2]; 2] = [[5.0 / 12.0, -1.0 / 12.0], [3.0 / 4.0, 1.0 / 4.0]];
    const C: [f64; 2] = [1.0 / 3.0, 1.0];
    let n = y.len();
    let mut z = vec![0.0; 2 * n];
    let mut f = [vec![0.0; n], vec![0.0; n]];
    for _ in 0..30 {
        // stage derivatives and Jacobians at the current iterate (full Newton)
        let ys: Vec<Vec<f64>> = (0..2)
            .map(|i| (0..n).map(|k| y[k] + z[i * n + k]).collect())
            .collect();
        let js: Vec<Vec<f64>> = (0..2)
            .map(|i| model.jacobian_dense(p, &ys[i], t + C[i] * h))
            .collect();
        for i in 0..2 {
            model.rhs(p, &ys[i], t + C[i] * h, &mut f[i]);
        }
        let mut g = vec![0.0; 2 * n];
        let mut m = vec![0.0; 4 * n * n];
        for i in 0..2 {
            for r in 0..n {
                g[i * n + r] = -(z[i * n + r] - h * (A[i][0] * f[0][r] + A[i][1] * f[1][r]));
                for j in 0..2 {
                    for c in 0..n {
                        let d = if i == j && r == c { 1.0 } else { 0.0 };
                        m[(i * n + r) * 2 * n + j * n + c] = d - h * A[i][j] * js[j][r + c * n];
                    }
                }
            }
        }
        let dz = solve(m, g, 2 * n);
        let norm = dz
            .iter()
            .zip(y.iter().chain(y))
            .map(|(d, s)| (d / s.abs().max(1e-3)).abs())
            .fold(0.0, f64::max);
        for k in 0..2 * n {
            z[k] += dz[k];
        }
        if norm < 1e-13 {
            break;
        }
    }
    (0..n).map(|k| y[k] + z[n + k]).collect()
}

fn compare(model: &dyn Model) {
    let p = model.default_params();
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(&p, &mut x0);
    x0[0] = 5e-3;
    x0[3] = -0.3;
    let (t_end, steps) = (0.02, 4000);
    let h = t_end / steps as f64;
    let mut y = x0.clone();
    for k in 0..steps {
        y = radau_step(model, &p, &y, k as f64 * h, h);
    }
    let opts = SimOptions {
        rtol: 1e-11,
        atol: 1e-11,
        ..Default::default()
    };
    let tr = sim::simulate(model, &p, &x0, t_end, &[t_end], &opts).unwrap();
    let scale = sim::state_scale(model, &p);
    let err = tr.x[0]
        .iter()
        .zip(&y)
        .zip(&scale)
        .map(|((a, b), s)| ((a - b) / s).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "{}: max scaled |BDF - Radau IIA| at t = {t_end} s: {err:.3e} ({} BDF steps)",
        model.name(),
        tr.stats.steps
    );
    assert!(
        err < 1e-8,
        "{}: BDF and Radau IIA differ by {err:e}",
        model.name()
    );
}

#[test]
fn bdf_agrees_with_radau_iia_on_cv1() {
    compare(&Cv1::new(1, Closure::Full).unwrap());
}

#[test]
fn bdf_agrees_with_radau_iia_on_nsection1() {
    compare(&NSection::new(1, Closure::Full).unwrap());
}
