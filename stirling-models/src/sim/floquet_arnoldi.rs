//! The leading Floquet multipliers (largest modulus) by Arnoldi on monodromy-vector
//! products, for cycles too large for the dense monodromy.
//!
//! **Operator.** `D^-1 Phi D` (state-scaled, the same spectrum as `Phi`) applied by
//! [`crate::sim::tangent::TangentFlow::apply`]. The spectrum of a stiff engine's monodromy is a
//! handful of multipliers of order one (the trivial 1, twice with the inventory, the slow thermal
//! and mechanical modes) and a cloud at `|mu| ~ 0` (the pressure-equalization modes, damped by
//! `exp(-T / tau)` with `tau` far below the period, and by L-stability of the Radau steps): plain
//! Arnoldi converges on the leading ones in a few dozen products.
//!
//! **Arnoldi.** Full reorthogonalization (classical Gram-Schmidt, twice), a fixed pseudo-random
//! start vector; every
//! [`ArnoldiOptions::check_every`](crate::sim::floquet_arnoldi::ArnoldiOptions::check_every) steps
//! the eigenvalues of the `j x j` Hessenberg matrix (nalgebra) give Ritz values, and the run stops
//! when the `k` leading ones moved by less than
//! [`ArnoldiOptions::tol`](crate::sim::floquet_arnoldi::ArnoldiOptions::tol) (relative to `max(1,
//! |mu|)`)
//! since the previous check, or on breakdown (an invariant subspace: the Ritz values are
//! then exact). The linear-analysis Arnoldi (`linear::dominant`) is complex shift-invert
//! with a Ritz-residual rule on faer LU solves; the pieces did not fit a real operator on a
//! closure, hence this small one.
//!
//! The double multiplier 1 of the `full` closure is a Jordan block (the period depends on
//! the inventory): like the dense eigen-solver, the Ritz values split it by about the
//! square root of the round-off of the products (~1e-8).

use nalgebra::DMatrix;

use super::SimError;

/// Settings of [`leading_multipliers`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ArnoldiOptions {
    /// Multipliers to return (a conjugate pair is never split, so up to `k + 1`).
    pub k: usize,
    /// Most Arnoldi steps (operator products).
    pub max_steps: usize,
    /// Steps between convergence checks.
    pub check_every: usize,
    /// Largest change of the leading Ritz values between checks.
    pub tol: f64,
}

impl Default for ArnoldiOptions {
    fn default() -> Self {
        Self {
            k: 8,
            max_steps: 120,
            check_every: 5,
            tol: 1e-10,
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A fixed pseudo-random unit vector (xorshift), so runs are reproducible.
fn start_vector(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut v: Vec<f64> = (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    let nv = dot(&v, &v).sqrt();
    v.iter_mut().for_each(|x| *x /= nv);
    v
}

/// Ritz values of the leading `j x j` block of `h`, largest modulus first.
fn ritz(h: &[Vec<f64>], j: usize) -> Vec<(f64, f64)> {
    ritz_values(&DMatrix::from_fn(j, j, |r, c| h[r][c]))
}

/// The eigenvalues of `m`, largest modulus first.
pub(super) fn ritz_values(m: &DMatrix<f64>) -> Vec<(f64, f64)> {
    let mut ev: Vec<(f64, f64)> = m
        .complex_eigenvalues()
        .iter()
        .map(|c| (c.re, c.im))
        .collect();
    ev.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
    ev
}

/// The `k` leading values, a trailing conjugate pair kept whole.
pub(super) fn leading(ev: &[(f64, f64)], k: usize) -> Vec<(f64, f64)> {
    let mut k = k.min(ev.len());
    if k > 0 && k < ev.len() && ev[k - 1].1 != 0.0 && ev[k].1 == -ev[k - 1].1 {
        k += 1;
    }
    ev[..k].to_vec()
}

/// Largest change between two lists of leading Ritz values (relative to `max(1, |mu|)`).
pub(super) fn change(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter()
        .zip(b)
        .map(|(x, y)| (x.0 - y.0).hypot(x.1 - y.1) / x.0.hypot(x.1).max(1.0))
        .fold(0.0, f64::max)
}

/// The leading multipliers of the operator `op` on `n`-vectors (`op(v)` in place) and
/// the products used.
pub fn leading_multipliers(
    op: &mut dyn FnMut(&mut [f64]) -> Result<(), SimError>,
    n: usize,
    opts: &ArnoldiOptions,
) -> Result<(Vec<(f64, f64)>, usize), SimError> {
    let m = opts.max_steps.min(n).max(1);
    let mut v = vec![start_vector(n)];
    let mut h = vec![vec![0.0; m]; m + 1];
    let mut last: Vec<(f64, f64)> = Vec::new();
    let mut moved = f64::INFINITY;
    for j in 0..m {
        let mut w = v[j].clone();
        op(&mut w)?;
        for _ in 0..2 {
            let c: Vec<f64> = v.iter().map(|vi| dot(&w, vi)).collect();
            for (vi, ci) in v.iter().zip(&c) {
                w.iter_mut().zip(vi).for_each(|(a, b)| *a -= ci * b);
            }
            c.iter().enumerate().for_each(|(i, ci)| h[i][j] += ci);
        }
        let hn = dot(&w, &w).sqrt();
        h[j + 1][j] = hn;
        let scale = (0..=j).map(|i| h[i][j].abs()).fold(hn, f64::max);
        let breakdown = hn <= 1e-14 * scale.max(f64::MIN_POSITIVE);
        if breakdown || (j + 1) % opts.check_every.max(1) == 0 || j + 1 == m {
            let now = leading(&ritz(&h, j + 1), opts.k);
            moved = change(&now, &last);
            last = now;
            if breakdown || moved < opts.tol {
                return Ok((last, j + 1));
            }
        }
        v.push(w.iter().map(|x| x / hn).collect());
    }
    if m == n {
        // the full space: the Ritz values are the eigenvalues
        return Ok((last, m));
    }
    Err(SimError::FloquetNotConverged {
        products: m,
        change: moved,
    })
}
