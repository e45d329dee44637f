//! The noise level of a sampled signal.

/// Noise standard deviation from third differences (the smooth signal cancels).
pub fn noise_sigma(y: &[f64]) -> f64 {
    if y.len() < 5 {
        return 0.0;
    }
    let mut d: Vec<f64> = (0..y.len() - 3)
        .map(|i| (y[i + 3] - 3.0 * y[i + 2] + 3.0 * y[i + 1] - y[i]).abs())
        .collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2] / 0.6745 / 20f64.sqrt()
}
