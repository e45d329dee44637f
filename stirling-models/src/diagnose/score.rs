//! **Which**: the score (Lagrange-multiplier) test of an omitted effect at its null.
//!
//! At the restricted optimum (the nominal calibration, effect strengths at their nulls) the
//! stacked weighted residuals `r` and Jacobian `J = [N, E]` (nuisance: every nominal
//! variable; tested: the effect strengths) give the effective score
//! `g = E_perp' r`, `E_perp = E - N (N'N)^-1 N'E` (the strength columns with what the nominal
//! parameters can absorb projected out). Its variance is estimated robustly: the per-sample
//! contributions `c_i = E_perp,i r~_i` are correlated in time (smoothed inputs, periodic model
//! error), so `V` is the Newey-West (Bartlett) long-run covariance of `c` within every output
//! series, centered. `r~ = r - E_perp (E_perp'E_perp)^-1 g` are the residuals after the
//! one-step fit of the effect: the null residuals would carry the effect's own periodic
//! signature, whose square inflates the long-run variance and sinks the power against large
//! effects (under the null the two agree to first order). Standardized independent rows
//! (priors on the nominal parameters) contribute `E_perp,i` with their known unit variance.
//! The statistic `g' V^-1 g` is chi-square with one degree of freedom per strength under the
//! null.
//!
//! Strengths that cannot be negative make the test one-sided: a strength whose one-step
//! estimate `-(E_perp'E_perp)^-1 g` is negative is dropped (held at its null) and the test is
//! repeated on the rest; a single bounded strength gets the chi-bar-square tail `P/2`.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use crate::signal::chi2_sf;

/// The result of a score test.
#[derive(Clone, Debug, Serialize)]
pub struct Score {
    pub stat: f64,
    /// Strengths tested (after dropping those pointing below their bound).
    pub dof: usize,
    pub p_value: f64,
    /// One-step estimate of every tested column (in the columns' units; 0 for dropped ones).
    pub step: Vec<f64>,
}

/// The Bartlett bandwidth for `n` samples per series and a cycle of `period` samples: the
/// Newey-West rule, at least a quarter cycle.
pub fn bandwidth(n: usize, period: usize) -> usize {
    let nw = (4.0 * (n as f64 / 100.0).powf(2.0 / 9.0)).ceil() as usize;
    nw.max(period / 4).min(n / 4).max(1)
}

/// Columns `test` of `j` with the span of the other columns projected out.
fn effective(j: &DMatrix<f64>, test: &[usize], skip: &[usize]) -> Option<DMatrix<f64>> {
    let nuis: Vec<usize> = (0..j.ncols())
        .filter(|c| !test.contains(c) && !skip.contains(c))
        .collect();
    let e = j.select_columns(test);
    if nuis.is_empty() {
        return Some(e);
    }
    let n = j.select_columns(&nuis);
    let mut ntn = n.transpose() * &n;
    let ridge = 1e-12 * (0..ntn.nrows()).map(|i| ntn[(i, i)]).fold(0.0, f64::max);
    for i in 0..ntn.nrows() {
        ntn[(i, i)] += ridge;
    }
    let b = ntn.cholesky()?.solve(&(n.transpose() * &e));
    Some(e - n * b)
}

/// Newey-West covariance of the rows of `c` (centered within every block of rows; a block of
/// one row is an independent term, e.g. a prior, and is not centered).
pub fn long_run_cov(c: &DMatrix<f64>, blocks: &[(usize, usize)], lag: usize) -> DMatrix<f64> {
    let k = c.ncols();
    let mut v = DMatrix::zeros(k, k);
    for &(a, b) in blocks {
        if b <= a {
            continue;
        }
        let mean: Vec<f64> = if b == a + 1 {
            vec![0.0; k]
        } else {
            (0..k)
                .map(|q| (a..b).map(|i| c[(i, q)]).sum::<f64>() / (b - a) as f64)
                .collect()
        };
        let x = DMatrix::from_fn(b - a, k, |i, q| c[(a + i, q)] - mean[q]);
        for l in 0..=lag.min(b - a - 1) {
            let w = if l == 0 {
                1.0
            } else {
                1.0 - l as f64 / (lag + 1) as f64
            };
            let m = b - a - l;
            let g = x.rows(l, m).transpose() * x.rows(0, m);
            if l == 0 {
                v += g * w;
            } else {
                v += (&g + g.transpose()) * w;
            }
        }
    }
    v
}

/// The robust one-sided score test of columns `test` of `j` at residuals `r`; `skip`: columns
/// that are neither tested nor nuisance (shape parameters, inert at the null); `bounded`: per
/// tested column; `blocks`: the rows of every time series (a block of one row: a standardized
/// independent row such as a prior); `lag`: the Bartlett bandwidth;
/// `noise`: draws of how the noise on the prescribed inputs moves `r` (their covariance of
/// the score is added: input noise driven through a lightly damped body is correlated over
/// longer than the record, which no bandwidth can estimate from the residuals alone).
pub fn robust_score(
    r: &[f64],
    j: &DMatrix<f64>,
    test: &[usize],
    skip: &[usize],
    bounded: &[bool],
    blocks: &[(usize, usize)],
    lag: usize,
    noise: &[Vec<f64>],
) -> Score {
    let mut active: Vec<usize> = (0..test.len()).collect();
    let rv = DVector::from_column_slice(r);
    let none = |dof| Score {
        stat: 0.0,
        dof,
        p_value: 1.0,
        step: vec![0.0; test.len()],
    };
    loop {
        if active.is_empty() {
            return none(0);
        }
        let cols: Vec<usize> = active.iter().map(|&a| test[a]).collect();
        let mut skipped: Vec<usize> = skip.to_vec();
        skipped.extend(test.iter().filter(|c| !cols.contains(c)));
        let Some(e) = effective(j, &cols, &skipped) else {
            return none(active.len());
        };
        let g = e.transpose() * &rv;
        let Some(step) = (e.transpose() * &e).cholesky().map(|c| -c.solve(&g)) else {
            return none(active.len());
        };
        if let Some(drop) = (0..active.len()).find(|&q| bounded[active[q]] && step[q] < 0.0) {
            active.remove(drop);
            continue;
        }
        let v = score_variance(&e, &rv, &step, blocks, lag, noise);
        let stat = match v.cholesky() {
            Some(ch) => g.dot(&ch.solve(&g)).max(0.0),
            None => return none(active.len()),
        };
        let dof = active.len();
        let mut p = chi2_sf(stat, dof);
        if dof == 1 && bounded[active[0]] {
            p *= 0.5;
        }
        let mut full = vec![0.0; test.len()];
        for (q, &a) in active.iter().enumerate() {
            full[a] = step[q];
        }
        return Score {
            stat,
            dof,
            p_value: p,
            step: full,
        };
    }
}

/// The covariance of the score `e' r`: the long-run covariance of its rows plus the draws of
/// the input noise.
fn score_variance(
    e: &DMatrix<f64>,
    rv: &DVector<f64>,
    step: &DVector<f64>,
    blocks: &[(usize, usize)],
    lag: usize,
    noise: &[Vec<f64>],
) -> DMatrix<f64> {
    // rows of the time series contribute `e_i r_i`; an independent row (a prior, a block
    // of one row) has unit variance by construction, so it contributes `e_i` (its own
    // squared residual would estimate its variance from one draw)
    let single: Vec<bool> = {
        let mut v = vec![false; e.nrows()];
        blocks
            .iter()
            .filter(|(a, b)| *b == a + 1)
            .for_each(|&(a, _)| v[a] = true);
        v
    };
    // the residuals with the one-step fit of the tested columns removed: under the
    // alternative the null residuals carry the effect's own periodic signature, and its
    // square would inflate the long-run variance (and sink the power for large effects)
    let r_alt = rv + e * step;
    let c = DMatrix::from_fn(e.nrows(), e.ncols(), |i, q| {
        e[(i, q)] * if single[i] { 1.0 } else { r_alt[i] }
    });
    let mut v = long_run_cov(&c, blocks, lag);
    if !noise.is_empty() {
        let mut acc = DMatrix::zeros(v.nrows(), v.ncols());
        for d in noise {
            let gd = e.transpose() * DVector::from_column_slice(d);
            acc += &gd * gd.transpose();
        }
        v += acc / noise.len() as f64;
    }
    v
}
