//! Filters: the first-order lag of a sensor and the projection of a slow drift band.

/// Exact first-order-hold discretization of `tau y' = u - y` on a uniform grid.
pub fn first_order_lag(u: &[f64], dt: f64, tau: f64) -> Vec<f64> {
    if tau <= 0.0 || u.is_empty() {
        return u.to_vec();
    }
    let a = (-dt / tau).exp();
    let c = 1.0 - tau / dt * (1.0 - a);
    let mut y = vec![u[0]; u.len()];
    for k in 1..u.len() {
        y[k] = a * y[k - 1] + (1.0 - a) * u[k - 1] + c * (u[k] - u[k - 1]);
    }
    y
}

/// Remove the cosines `k = 1..=m` (DCT-II, orthogonal on the uniform grid) from `v`.
pub fn project_drift(v: &mut [f64], m: usize) {
    let n = v.len();
    if n < 2 {
        return;
    }
    for k in 1..=m.min(n - 1) {
        let b: Vec<f64> = (0..n)
            .map(|i| (std::f64::consts::PI * k as f64 * (i as f64 + 0.5) / n as f64).cos())
            .collect();
        let c = v.iter().zip(&b).map(|(a, b)| a * b).sum::<f64>() / (n as f64 / 2.0);
        v.iter_mut().zip(&b).for_each(|(a, b)| *a -= c * b);
    }
}

/// Number of cosines of [`project_drift`] below `f_cut` (Hz) on `n` samples of interval `dt`.
pub fn drift_count(n: usize, dt: f64, f_cut: f64) -> usize {
    if !(f_cut > 0.0) || n < 2 {
        return 0;
    }
    ((2.0 * n as f64 * dt * f_cut).floor() as usize).min(n / 4)
}
