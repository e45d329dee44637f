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
///
/// The cosines depend only on `(n, k)`: they are computed once per thread and kept (`cosine`), so
/// the fits, which project every residual and Jacobian column at every evaluation, do not recompute
/// them (they took 4 % of a diagnosis).
pub fn project_drift(v: &mut [f64], m: usize) {
    let n = v.len();
    if n < 2 {
        return;
    }
    for k in 1..=m.min(n - 1) {
        let b = cosine(n, k);
        let c = v.iter().zip(b.iter()).map(|(a, b)| a * b).sum::<f64>() / (n as f64 / 2.0);
        v.iter_mut().zip(b.iter()).for_each(|(a, b)| *a -= c * b);
    }
}

/// Most cosines kept per thread (a record's few window lengths times their drift counts
/// stay far below; past it the cache starts over).
const COSINE_CACHE: usize = 512;

thread_local! {
    static COSINES: std::cell::RefCell<std::collections::HashMap<(usize, usize), std::rc::Rc<[f64]>>> =
        std::cell::RefCell::new(std::collections::HashMap::new());
}

/// The cosine `cos(pi k (i + 1/2) / n)`, `i = 0..n`, from this thread's cache.
fn cosine(n: usize, k: usize) -> std::rc::Rc<[f64]> {
    COSINES.with(|c| {
        let mut c = c.borrow_mut();
        if let Some(b) = c.get(&(n, k)) {
            return b.clone();
        }
        if c.len() >= COSINE_CACHE {
            c.clear();
        }
        let b: std::rc::Rc<[f64]> = (0..n)
            .map(|i| (std::f64::consts::PI * k as f64 * (i as f64 + 0.5) / n as f64).cos())
            .collect();
        c.insert((n, k), b.clone());
        b
    })
}

/// Number of cosines of [`project_drift`] below `f_cut` (Hz) on `n` samples of interval `dt`.
pub fn drift_count(n: usize, dt: f64, f_cut: f64) -> usize {
    if !(f_cut > 0.0) || n < 2 {
        return 0;
    }
    ((2.0 * n as f64 * dt * f_cut).floor() as usize).min(n / 4)
}
