//! Smoothing and derivatives of uniformly sampled signals.

use nalgebra::{DMatrix, DVector};

/// Savitzky-Golay smoothing (local polynomial of `degree` over `2h+1` samples): value and
/// first derivative at every sample (windows shifted inside the record at the ends).
pub fn savitzky_golay(y: &[f64], dt: f64, h: usize, degree: usize) -> (Vec<f64>, Vec<f64>) {
    let n = y.len();
    let h = h.min((n - 1) / 2).max(1);
    let w = 2 * h + 1;
    let deg = degree.min(w - 1);
    // weights for evaluation point at offset `c` from the window start
    let a = DMatrix::from_fn(w, deg + 1, |i, k| {
        ((i as f64 - h as f64) / h as f64).powi(k as i32)
    });
    let pinv = (a.transpose() * &a)
        .try_inverse()
        .expect("Vandermonde of distinct points")
        * a.transpose();
    let weights = |c: usize| -> (DVector<f64>, DVector<f64>) {
        let s = (c as f64 - h as f64) / h as f64;
        let v = DVector::from_fn(deg + 1, |k, _| s.powi(k as i32));
        let d = DVector::from_fn(deg + 1, |k, _| {
            if k == 0 {
                0.0
            } else {
                k as f64 * s.powi(k as i32 - 1) / (h as f64 * dt)
            }
        });
        (pinv.transpose() * v, pinv.transpose() * d)
    };
    let mid = weights(h);
    let mut val = vec![0.0; n];
    let mut der = vec![0.0; n];
    for i in 0..n {
        let start = i.saturating_sub(h).min(n - w);
        let c = i - start;
        let owned;
        let (wv, wd) = if c == h {
            (&mid.0, &mid.1)
        } else {
            owned = weights(c);
            (&owned.0, &owned.1)
        };
        let seg = &y[start..start + w];
        val[i] = seg.iter().zip(wv.iter()).map(|(a, b)| a * b).sum();
        der[i] = seg.iter().zip(wd.iter()).map(|(a, b)| a * b).sum();
    }
    (val, der)
}

/// Central-difference derivative of uniform samples (one-sided at the ends).
pub fn derivative(y: &[f64], dt: f64) -> Vec<f64> {
    let n = y.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            if b > a {
                (y[b] - y[a]) / ((b - a) as f64 * dt)
            } else {
                0.0
            }
        })
        .collect()
}

/// Remove the centered moving average of half-width `h` (over the finite samples), scaled so
/// that white noise keeps its variance.
pub fn high_pass(r: &[f64], h: usize) -> Vec<f64> {
    let n = r.len();
    let mut cs = vec![0.0; n + 1];
    let mut cn = vec![0usize; n + 1];
    for i in 0..n {
        let ok = r[i].is_finite();
        cs[i + 1] = cs[i] + if ok { r[i] } else { 0.0 };
        cn[i + 1] = cn[i] + ok as usize;
    }
    let w = (2 * h + 1) as f64;
    let gain = 1.0 / (1.0 - 1.0 / w).sqrt();
    (0..n)
        .map(|i| {
            if !r[i].is_finite() || h == 0 {
                return r[i];
            }
            let (a, b) = (i.saturating_sub(h), (i + h + 1).min(n));
            let m = (cs[b] - cs[a]) / (cn[b] - cn[a]).max(1) as f64;
            gain * (r[i] - m)
        })
        .collect()
}
