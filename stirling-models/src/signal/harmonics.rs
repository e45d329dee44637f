//! Harmonics of a signal over whole cycles.

/// Least-squares `c + a cos(wt) + b sin(wt)`: returns `(amplitude, phase)`.
pub fn fundamental(y: &[f64], dt: f64, f: f64) -> (f64, f64) {
    let w = 2.0 * std::f64::consts::PI * f;
    let mut a = nalgebra::Matrix3::<f64>::zeros();
    let mut g = nalgebra::Vector3::<f64>::zeros();
    for (i, &v) in y.iter().enumerate() {
        let t = i as f64 * dt;
        let r = nalgebra::Vector3::new(1.0, (w * t).cos(), (w * t).sin());
        a += r * r.transpose();
        g += r * v;
    }
    let c = a.lu().solve(&g).unwrap_or_else(nalgebra::Vector3::zeros);
    // a cos + b sin = A cos(wt - phi): phase = -phi
    ((c[1] * c[1] + c[2] * c[2]).sqrt(), -(c[2].atan2(c[1])))
}

pub fn dft(r: &[f64], period_samples: f64, k: usize) -> (f64, f64) {
    let n = r.len() as f64;
    let (mut re, mut im) = (0.0, 0.0);
    for (i, v) in r.iter().enumerate() {
        let ph = 2.0 * std::f64::consts::PI * k as f64 * i as f64 / period_samples;
        re += v * ph.cos();
        im -= v * ph.sin();
    }
    let s = if k == 0 { 1.0 / n } else { 2.0 / n };
    (s * re, s * im)
}

pub fn wrap(a: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    let mut v = a % tau;
    if v <= -std::f64::consts::PI {
        v += tau;
    } else if v > std::f64::consts::PI {
        v -= tau;
    }
    v
}
