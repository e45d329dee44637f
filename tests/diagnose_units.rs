//! Gap diagnosis: the statistics it is built on (cheap, no simulation).

use nalgebra::{DMatrix, DVector};
use stirling::models::diagnose::score::{bandwidth, long_run_cov, robust_score};
use stirling::models::signal::{chi2_sf, erfc, high_pass};

#[test]
fn chi_square_tails() {
    // chi2(1): P(X > 3.841) = 0.05, P(X > 6.635) = 0.01; chi2(2): exp(-x/2)
    assert!((chi2_sf(3.841, 1) - 0.05).abs() < 2e-4);
    assert!((chi2_sf(6.635, 1) - 0.01).abs() < 1e-4);
    assert!((chi2_sf(5.991, 2) - 0.05).abs() < 1e-4);
    assert_eq!(chi2_sf(0.0, 1), 1.0);
    assert!(
        (erfc(0.0) - 1.0).abs() < 1e-7
            && (erfc(1.0) - 0.157_299_2).abs() < 1e-6
            && (erfc(-1.0) - 1.842_700_8).abs() < 1e-6
    );
}

#[test]
fn high_pass_removes_slow_parts_and_keeps_white_noise() {
    let n = 4000;
    // a slow drift plus a fast tone
    let r: Vec<f64> = (0..n)
        .map(|i| 3.0 + 1e-3 * i as f64 + (i as f64 * 0.9).sin())
        .collect();
    let hp = high_pass(&r, 35);
    let mean: f64 = hp[100..n - 100].iter().sum::<f64>() / (n - 200) as f64;
    assert!(mean.abs() < 0.02, "drift left: {mean}");
    // white noise keeps its variance (the gain corrects for the removed average)
    let mut s = 12345u64;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let w: Vec<f64> = (0..20000).map(|_| u() * 12f64.sqrt()).collect();
    let hw = high_pass(&w, 35);
    let var = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
    assert!(
        (var(&hw) / var(&w) - 1.0).abs() < 0.03,
        "variance ratio {}",
        var(&hw) / var(&w)
    );
}

/// A small deterministic generator (LCG) of standard normal draws (Box-Muller).
fn normals(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    let mut u = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    move || (-2.0 * u().ln()).sqrt() * (2.0 * std::f64::consts::PI * u()).cos()
}

/// A regression `y = a cos + b sin + noise` with AR(1) noise (correlation `rho`), fitted
/// without the column `t sin` (the omitted effect, true coefficient `c`): residuals and the
/// Jacobian `[cos, sin, t sin]` at the restricted least-squares optimum.
fn restricted(c: f64, rho: f64, seed: u64) -> (Vec<f64>, DMatrix<f64>) {
    let n = 600;
    let mut z = normals(seed);
    let mut e = 0.0;
    let cols = DMatrix::from_fn(n, 3, |i, k| {
        let w = 0.21 * i as f64;
        match k {
            0 => w.cos(),
            1 => w.sin(),
            _ => i as f64 / n as f64 * w.sin(),
        }
    });
    let y: Vec<f64> = (0..n)
        .map(|i| {
            e = rho * e + (1.0 - rho * rho).sqrt() * z();
            2.0 * cols[(i, 0)] - cols[(i, 1)] + c * cols[(i, 2)] + e
        })
        .collect();
    let x = cols.columns(0, 2).into_owned();
    let yv = DVector::from_vec(y);
    let beta = (x.transpose() * &x)
        .cholesky()
        .unwrap()
        .solve(&(x.transpose() * &yv));
    // residuals as model minus data, like the fit's
    let r = (&x * beta - yv).iter().copied().collect();
    (r, cols)
}

#[test]
fn robust_score_has_its_size_under_correlated_noise_and_power_against_the_effect() {
    let blocks = [(0, 600)];
    let lag = bandwidth(600, 30);
    let mut rejections = 0;
    let reps = 300;
    for s in 0..reps {
        let (r, j) = restricted(0.0, 0.6, 1000 + s);
        let sc = robust_score(&r, &j, &[2], &[], &[false], &blocks, lag, &[]);
        assert_eq!(sc.dof, 1);
        if sc.p_value < 0.05 {
            rejections += 1;
        }
    }
    // nominal size 5 %: AR(1) noise with rho = 0.6 would triple a naive test's rate
    let rate = rejections as f64 / reps as f64;
    assert!((0.01..=0.11).contains(&rate), "size {rate}");
    // the omitted column at a strength of a few noise levels is found, with the right sign
    let (r, j) = restricted(1.0, 0.6, 7);
    let sc = robust_score(&r, &j, &[2], &[], &[true], &blocks, lag, &[]);
    assert!(sc.p_value < 1e-3 && sc.step[0] > 0.0, "{sc:?}");
    // one-sided: a negative effect of a strength bounded at zero is not evidence
    let (r, j) = restricted(-1.0, 0.6, 7);
    let sc = robust_score(&r, &j, &[2], &[], &[true], &blocks, lag, &[]);
    assert_eq!((sc.dof, sc.p_value), (0, 1.0));
}

#[test]
fn long_run_covariance_of_white_rows_is_their_sum_of_squares() {
    let mut z = normals(3);
    let c = DMatrix::from_fn(5000, 1, |_, _| z());
    let v = long_run_cov(&c, &[(0, 5000)], 0);
    assert!((v[(0, 0)] / 5000.0 - 1.0).abs() < 0.05, "{}", v[(0, 0)]);
    // with a bandwidth, white rows stay close (the cross terms average out)
    let v10 = long_run_cov(&c, &[(0, 5000)], 10);
    assert!((v10[(0, 0)] / v[(0, 0)] - 1.0).abs() < 0.15);
}

#[test]
fn single_row_blocks_are_independent_terms_not_centered() {
    // a prior row is one standardized draw: its block of one row keeps its square
    let c = DMatrix::from_row_slice(2, 1, &[2.0, 3.0]);
    let v = long_run_cov(&c, &[(0, 1), (1, 2)], 5);
    assert!((v[(0, 0)] - 13.0).abs() < 1e-12, "{}", v[(0, 0)]);
    // the same rows as one series are centered
    let v2 = long_run_cov(&c, &[(0, 2)], 0);
    assert!((v2[(0, 0)] - 0.5).abs() < 1e-12, "{}", v2[(0, 0)]);
}

#[test]
fn robust_score_keeps_its_power_as_the_effect_grows() {
    // the variance comes from the residuals after the one-step fit, so the effect's own
    // signature does not inflate it: the statistic grows like the squared strength (with
    // the null residuals it would saturate, numerator and variance both growing like c^2)
    let blocks = [(0, 600)];
    let lag = bandwidth(600, 30);
    let stat = |c: f64| {
        let (r, j) = restricted(c, 0.6, 11);
        robust_score(&r, &j, &[2], &[], &[false], &blocks, lag, &[]).stat
    };
    let (s2, s8) = (stat(2.0), stat(8.0));
    assert!(s8 > 8.0 * s2, "stat(8) = {s8}, stat(2) = {s2}");
}
