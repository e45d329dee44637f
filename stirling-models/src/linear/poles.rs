//! Eigenvalues of a state matrix as poles: `det(sI - A) = 0`.
//!
//! The matrix is balanced first ([`crate::linear::balance`]); the eigenvalues come from faer's real
//! Schur decomposition, which is fast enough for `nsection` at n = 1000 (2007 dynamic states).
//! Conjugate pairs are made exactly symmetric. Poles are sorted by decreasing real part (the least
//! stable first); within a pair the positive imaginary part comes first.

use faer::Mat;
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::balance::balance;
use super::LinearError;

/// One pole `s = re + j im`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pole {
    pub re: f64,
    pub im: f64,
    /// Damped frequency `|im|` (rad/s).
    pub freq_rad_s: f64,
    /// `|im| / 2 pi` (Hz).
    pub freq_hz: f64,
    /// Natural frequency `|s|` (rad/s).
    pub natural_rad_s: f64,
    /// Growth rate `re` (1/s; positive: the mode grows).
    pub growth_rate: f64,
    /// Damping ratio `-re / |s|` (0 for `s = 0`).
    pub damping_ratio: f64,
    /// In the open right half plane (`re > 0`).
    pub rhp: bool,
}

impl Pole {
    /// The pole at `re + j im`.
    pub fn new(re: f64, im: f64) -> Self {
        let wn = re.hypot(im);
        Self {
            re,
            im,
            freq_rad_s: im.abs(),
            freq_hz: im.abs() / (2.0 * std::f64::consts::PI),
            natural_rad_s: wn,
            growth_rate: re,
            damping_ratio: if wn > 0.0 { -re / wn } else { 0.0 },
            rhp: re > 0.0,
        }
    }
}

/// Eigenvalues `(re, im)` of `a`, balanced, unsorted.
pub fn eigenvalues(a: &DMatrix<f64>) -> Result<Vec<(f64, f64)>, LinearError> {
    let n = a.nrows();
    if n == 0 {
        return Ok(Vec::new());
    }
    if a.iter().any(|v| !v.is_finite()) {
        return Err(LinearError::NonFinite {
            what: "state matrix",
        });
    }
    let (b, _) = balance(a);
    let m = Mat::<f64>::from_fn(n, n, |i, j| b[(i, j)]);
    let ev = m
        .eigenvalues()
        .map_err(|e| LinearError::Eigen(format!("{e:?}")))?;
    Ok(ev.into_iter().map(|c| (c.re, c.im)).collect())
}

/// Poles of `a`, sorted (see the module docs), conjugate pairs symmetric.
pub fn poles(a: &DMatrix<f64>) -> Result<Vec<Pole>, LinearError> {
    Ok(to_poles(eigenvalues(a)?))
}

/// Sort eigenvalues into poles; imaginary parts below `1e-10 |s|` are set to zero.
pub fn to_poles(mut ev: Vec<(f64, f64)>) -> Vec<Pole> {
    for e in &mut ev {
        if e.1.abs() <= 1e-10 * e.0.hypot(e.1) {
            e.1 = 0.0;
        }
    }
    // Symmetrize pairs: average each upper-half eigenvalue with its nearest lower-half partner.
    let (mut upper, lower): (Vec<_>, Vec<_>) = ev
        .iter()
        .copied()
        .filter(|e| e.1 != 0.0)
        .partition(|e| e.1 > 0.0);
    let mut used = vec![false; lower.len()];
    for u in &mut upper {
        let best = (0..lower.len())
            .filter(|&k| !used[k])
            .min_by(|&a, &b| dist(*u, lower[a]).total_cmp(&dist(*u, lower[b])));
        if let Some(k) = best {
            used[k] = true;
            *u = ((u.0 + lower[k].0) / 2.0, (u.1 - lower[k].1) / 2.0);
        }
    }
    let mut out: Vec<Pole> = ev
        .iter()
        .filter(|e| e.1 == 0.0)
        .map(|e| Pole::new(e.0, 0.0))
        .collect();
    for u in upper {
        out.push(Pole::new(u.0, u.1));
        out.push(Pole::new(u.0, -u.1));
    }
    out.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    out
}

fn dist(u: (f64, f64), l: (f64, f64)) -> f64 {
    (u.0 - l.0).hypot(u.1 + l.1)
}
