//! Gap diagnosis: the statistics it is built on (cheap, no simulation).

use stirling::models::diagnose::score::Quad;
use stirling::models::diagnose::{chi2_sf, erfc, high_pass, Eval};

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

fn point(theta: Vec<f64>, s: f64) -> Eval {
    Eval {
        theta,
        s_train: s,
        n_train: 100,
        holdout_error: 1.0,
        train_error: 1.0,
        channels: vec![],
        resid: vec![],
        hp: vec![],
        pred: vec![],
        p: vec![],
    }
}

#[test]
fn quadratic_profile_model_and_one_sided_score() {
    // S(a, b) = 10 + 2a - 4b + 3a^2 + ab + 2b^2, exact through six points
    let s = |a: f64, b: f64| 10.0 + 2.0 * a - 4.0 * b + 3.0 * a * a + a * b + 2.0 * b * b;
    let pts: Vec<Eval> = [
        (0.0, 0.0),
        (0.1, 0.0),
        (0.2, 0.0),
        (0.0, 0.1),
        (0.0, 0.2),
        (0.1, 0.1),
    ]
    .iter()
    .map(|&(a, b)| point(vec![a, b], s(a, b)))
    .collect();
    let refs: Vec<&Eval> = pts.iter().collect();
    let q = Quad::fit(&refs, &[0.0, 0.0], &[0.1, 0.1]).unwrap();
    assert!(
        (q.g[0] - 2.0).abs() < 1e-8 && (q.g[1] + 4.0).abs() < 1e-8,
        "{:?}",
        q.g
    );
    assert!(
        (q.h[0][0] - 6.0).abs() < 1e-6
            && (q.h[0][1] - 1.0).abs() < 1e-6
            && (q.h[1][1] - 4.0).abs() < 1e-6,
        "{:?}",
        q.h
    );
    // unconstrained g' H^-1 g
    let det = 6.0 * 4.0 - 1.0;
    let full = (2.0 * 2.0 * 4.0 - 2.0 * 2.0 * (-4.0) * 1.0 + 16.0 * 6.0) / det;
    assert!((q.quad_form(&[false, false], true) - full).abs() < 1e-6);
    // one-sided: `a` would have to go negative to lower the cost, so only `b` counts
    assert!((q.quad_form(&[true, true], true) - 16.0 / 4.0).abs() < 1e-6);
}
