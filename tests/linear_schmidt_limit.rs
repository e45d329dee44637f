//! docs/physics.md section 10: with large heat transfer and small flow resistance, `nsection` tends to
//! `schmidt`. At finite n the limit is the Schmidt model whose regenerator temperature is the
//! harmonic mean of the n section wall temperatures; the log-mean (section 3) is reached as
//! O(1/n^2). Reference values: 40-digit eigenvalues of the independent Python check.

use stirling::dsl::{Closure, Model};
use stirling::models::linear::{self, NewtonOptions};

type Pair = (f64, f64);

fn set(model: &dyn Model, p: &mut [f64], name: &str, v: f64) {
    p[model.param_index(name).unwrap()] = v;
}

/// The two dominant complex pairs (upper half), least stable first.
fn dominant(model: &dyn Model, p: &[f64]) -> Vec<Pair> {
    let d = linear::dynamic_poles(model, p, &NewtonOptions::default()).unwrap();
    d.poles
        .iter()
        .filter(|q| q.im > 1.0 && q.natural_rad_s < 1e3)
        .map(|q| (q.re, q.im))
        .collect()
}

fn distance(a: &[Pair], b: &[Pair]) -> f64 {
    assert_eq!(a.len(), 2, "{a:?}");
    a.iter()
        .zip(b)
        .map(|(x, y)| (x.0 - y.0).hypot(x.1 - y.1))
        .fold(0.0, f64::max)
}

fn nsection_limit(n: usize) -> Vec<Pair> {
    let model = stirling::models::build("nsection", Some(n), Closure::Full).unwrap();
    let mut p = model.default_params();
    for h in ["hh", "hk", "hr"] {
        set(model.as_ref(), &mut p, h, 1e6);
    }
    set(model.as_ref(), &mut p, "Rf", 1.0);
    dominant(model.as_ref(), &p)
}

/// Schmidt with `Vr/Tr` at the harmonic mean `Tr_n` of the n section wall temperatures
/// (realized as `Vr -> Vr Tr_log / Tr_n`, since `schmidt` uses the log-mean).
fn schmidt_at(tr_n: Option<f64>) -> Vec<Pair> {
    let model = stirling::models::build("schmidt", None, Closure::Full).unwrap();
    let mut p = model.default_params();
    let get = |p: &[f64], n: &str| p[model.param_index(n).unwrap()];
    if let Some(tr) = tr_n {
        let (th, tk) = (get(&p, "Th"), get(&p, "Tk"));
        let tr_log = (th - tk) / (th / tk).ln();
        let vr = get(&p, "Vr") * tr_log / tr;
        set(model.as_ref(), &mut p, "Vr", vr);
    }
    dominant(model.as_ref(), &p)
}

fn harmonic_tr(n: usize, th: f64, tk: f64) -> f64 {
    let inv: f64 = (1..=n)
        .map(|j| 1.0 / (th - (j as f64 - 0.5) * (th - tk) / n as f64))
        .sum();
    n as f64 / inv
}

#[test]
fn nsection_tends_to_schmidt() {
    let schmidt = schmidt_at(None);
    // (n, pair 1, pair 2) in 40-digit arithmetic (report section 5, h = 1e6, Rf = 1).
    let reference = [
        (1, (9.6343, 89.6135), (-25.2061, 94.2814)),
        (2, (9.6235, 89.5581), (-25.1973, 94.1768)),
        (4, (9.6202, 89.5426), (-25.1950, 94.1462)),
        (8, (9.6192, 89.5387), (-25.1946, 94.1379)),
    ];
    let mut last = f64::INFINITY;
    for (n, r1, r2) in reference {
        let got = nsection_limit(n);
        assert!(distance(&got, &[r1, r2]) < 2e-3, "n = {n}: {got:?}");
        let d_log = distance(&got, &schmidt);
        assert!(d_log < last, "n = {n}: distance {d_log} does not decrease");
        last = d_log;
        let d_harm = distance(&got, &schmidt_at(Some(harmonic_tr(n, 600.0, 300.0))));
        assert!(
            d_harm < 1e-2,
            "n = {n}: distance to the harmonic-mean Schmidt {d_harm}"
        );
        println!(
            "| {n} | {:.4} ± {:.4}j | {:.4} ± {:.4}j | {d_log:.2e} | {d_harm:.2e} | {:.2e} |",
            got[0].0,
            got[0].1,
            got[1].0,
            got[1].1,
            distance(&got, &[r1, r2])
        );
    }
    assert!(last < 1e-2, "n = 8: {last}");
}
