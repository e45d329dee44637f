//! Restarted GMRES on a matrix-free operator (the Newton-Krylov shooting system).
//!
//! Arnoldi with modified Gram-Schmidt applied twice (the basis stays orthogonal to
//! round-off, which matters when the operator is `-I` plus a low-rank part and the
//! residual drops by ten orders in a few dozen steps), Givens rotations on the
//! Hessenberg matrix, restart after `restart` steps. No maintained Rust crate offers
//! GMRES on a fallible closure over `&[f64]` (the sparse crates' iterative solvers
//! want their own matrix types), hence these ~100 lines.

use super::SimError;

/// The result of [`gmres`].
#[derive(Clone, Debug, PartialEq)]
pub struct GmresSolution {
    pub x: Vec<f64>,
    /// Operator applications.
    pub iterations: usize,
    /// Final residual `|b - A x| / |b|` (the recurrence's estimate).
    pub relative_residual: f64,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// Solve `A x = b` from `x = 0` until `|b - A x| <= tol |b|` or `max_iter` products.
pub fn gmres(
    op: &mut dyn FnMut(&[f64], &mut [f64]) -> Result<(), SimError>,
    b: &[f64],
    tol: f64,
    restart: usize,
    max_iter: usize,
) -> Result<GmresSolution, SimError> {
    let n = b.len();
    let mut x = vec![0.0; n];
    let bnorm = norm(b);
    if bnorm == 0.0 {
        return Ok(GmresSolution {
            x,
            iterations: 0,
            relative_residual: 0.0,
        });
    }
    let mut r = b.to_vec();
    let (mut iterations, mut rel) = (0, 1.0);
    let mut ax = vec![0.0; n];
    while iterations < max_iter {
        let (dx, used, est) = cycle(op, &r, tol * bnorm, restart.min(max_iter - iterations))?;
        iterations += used;
        for (xi, d) in x.iter_mut().zip(&dx) {
            *xi += d;
        }
        op(&x, &mut ax)?;
        iterations += 1;
        for i in 0..n {
            r[i] = b[i] - ax[i];
        }
        rel = norm(&r) / bnorm;
        if rel <= tol || est == 0.0 || used == 0 {
            break;
        }
    }
    Ok(GmresSolution {
        x,
        iterations,
        relative_residual: rel,
    })
}

/// One GMRES cycle of at most `m` steps from residual `r0`: the correction, the products
/// used and the estimated residual norm.
fn cycle(
    op: &mut dyn FnMut(&[f64], &mut [f64]) -> Result<(), SimError>,
    r0: &[f64],
    abs_tol: f64,
    m: usize,
) -> Result<(Vec<f64>, usize, f64), SimError> {
    let n = r0.len();
    let beta = norm(r0);
    let mut v: Vec<Vec<f64>> = vec![r0.iter().map(|x| x / beta).collect()];
    let mut h = vec![vec![0.0; m]; m + 1];
    let (mut cs, mut sn) = (vec![0.0; m], vec![0.0; m]);
    let mut g = vec![0.0; m + 1];
    g[0] = beta;
    let mut k = 0;
    while k < m {
        let mut w = vec![0.0; n];
        op(&v[k], &mut w)?;
        for _ in 0..2 {
            for (i, vi) in v.iter().enumerate() {
                let c = dot(&w, vi);
                h[i][k] += c;
                w.iter_mut().zip(vi).for_each(|(a, b)| *a -= c * b);
            }
        }
        let hn = norm(&w);
        h[k + 1][k] = hn;
        for i in 0..k {
            let t = cs[i] * h[i][k] + sn[i] * h[i + 1][k];
            h[i + 1][k] = -sn[i] * h[i][k] + cs[i] * h[i + 1][k];
            h[i][k] = t;
        }
        let d = h[k][k].hypot(h[k + 1][k]);
        (cs[k], sn[k]) = if d == 0.0 {
            (1.0, 0.0)
        } else {
            (h[k][k] / d, h[k + 1][k] / d)
        };
        h[k][k] = d;
        h[k + 1][k] = 0.0;
        g[k + 1] = -sn[k] * g[k];
        g[k] *= cs[k];
        k += 1;
        if g[k].abs() <= abs_tol || hn == 0.0 {
            break;
        }
        v.push(w.iter().map(|x| x / hn).collect());
    }
    // back substitution on the k x k triangle
    let mut y = vec![0.0; k];
    for i in (0..k).rev() {
        let s: f64 = (i + 1..k).map(|j| h[i][j] * y[j]).sum();
        y[i] = if h[i][i] == 0.0 {
            0.0
        } else {
            (g[i] - s) / h[i][i]
        };
    }
    let mut dx = vec![0.0; n];
    for (yi, vi) in y.iter().zip(&v) {
        dx.iter_mut().zip(vi).for_each(|(a, b)| *a += yi * b);
    }
    Ok((dx, k, g[k].abs()))
}
