//! The solves with the factors of [`crate::sim::refactor_lu::RefactorLu`]: `x <- Q U^-1 L^-1 P x`,
//! one right-hand side (the integrator's Newton steps) or many at once (the dense monodromy's
//! columns). Two versions on purpose: the one-column sweep is the simulation's hot path and stays a
//! plain loop; the many-column one runs each factor entry over all columns.

use super::{LuPattern, LuValues};

/// Permute, two column sweeps, permute back.
pub(super) fn solve_with(p: &LuPattern, v: &LuValues, x: &mut [f64], y: &mut [f64]) {
    for (yi, &r) in y.iter_mut().zip(&p.row_perm) {
        *yi = x[r];
    }
    let (lp, li, lv) = (&p.l_ptr[..], &p.l_idx[..], &v.l[..]);
    for j in 0..y.len() {
        let yj = y[j];
        let (a, b) = (lp[j] + 1, lp[j + 1]);
        for (&i, &l) in li[a..b].iter().zip(&lv[a..b]) {
            y[i] -= l * yj;
        }
    }
    let (up, ui, uv, dinv) = (&p.u_ptr[..], &p.u_idx[..], &v.u[..], &v.u_inv_diag[..]);
    for j in (0..y.len()).rev() {
        let yj = y[j] * dinv[j];
        y[j] = yj;
        let (a, b) = (up[j], up[j + 1] - 1);
        for (&i, &u) in ui[a..b].iter().zip(&uv[a..b]) {
            y[i] -= u * yj;
        }
    }
    for (&yj, &c) in y.iter().zip(&p.col_perm) {
        x[c] = yj;
    }
}

/// [`solve_with`] for `k` columns at once: the work holds the permuted right-hand sides row
/// by row, so every update of a factor entry runs over the `k` columns contiguously.
pub(super) fn solve_many(p: &LuPattern, v: &LuValues, x: &mut [f64], k: usize, y: &mut Vec<f64>) {
    let n = p.row_perm.len();
    y.clear();
    y.resize(n * k, 0.0);
    for (i, &r) in p.row_perm.iter().enumerate() {
        for c in 0..k {
            y[i * k + c] = x[c * n + r];
        }
    }
    let axpy = |y: &mut [f64], dst: usize, src: usize, f: f64| {
        let (d, s) = if dst > src {
            let (lo, hi) = y.split_at_mut(dst * k);
            (&mut hi[..k], &lo[src * k..src * k + k])
        } else {
            let (lo, hi) = y.split_at_mut(src * k);
            (&mut lo[dst * k..dst * k + k], &hi[..k])
        };
        for (a, b) in d.iter_mut().zip(s) {
            *a -= f * b;
        }
    };
    for j in 0..n {
        for e in p.l_ptr[j] + 1..p.l_ptr[j + 1] {
            axpy(y, p.l_idx[e], j, v.l[e]);
        }
    }
    for j in (0..n).rev() {
        let d = v.u_inv_diag[j];
        y[j * k..j * k + k].iter_mut().for_each(|a| *a *= d);
        for e in p.u_ptr[j]..p.u_ptr[j + 1] - 1 {
            axpy(y, p.u_idx[e], j, v.u[e]);
        }
    }
    for (j, &c) in p.col_perm.iter().enumerate() {
        for col in 0..k {
            x[col * n + c] = y[j * k + col];
        }
    }
}
