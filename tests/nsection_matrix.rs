//! The core of `examples/nsection_matrix.rs`: a regenerator matrix of finite heat capacity on
//! `nsection` (declared by extending the family's `nsection_engine`). As the capacity grows
//! the dominant poles converge to the fixed-wall model's (tenfold closer per decade); the
//! matrix lowers the indicated power, the more the smaller its capacity.

#[path = "../examples/support/matrix_study.rs"]
mod matrix_study;

use matrix_study::{fixed_case, matrix_case, NSectionMatrix};
use stirling::dsl::{Closure, Model};
use stirling::models::linear::{self, NewtonOptions};

/// The dominant (rightmost oscillating) pole at `km`.
fn pole(m: &dyn Model, km: f64) -> (f64, f64) {
    let mut p = m.default_params();
    p[m.param_index("km").unwrap()] = km;
    let d = linear::dynamic_poles(m, &p, &NewtonOptions::default()).unwrap();
    d.poles
        .iter()
        .filter(|q| q.im > 0.0)
        .map(|q| (q.re, q.im))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .unwrap()
}

#[test]
fn poles_converge_to_the_fixed_wall() {
    let n = 3;
    let fixed = fixed_case(n, "fixed", 8.0).unwrap();
    let m = NSectionMatrix::new(n, Closure::Full).unwrap();
    let d: Vec<f64> = [1.0, 0.1, 0.01, 0.001]
        .iter()
        .map(|&km| {
            let q = pole(&m, km);
            (q.0 - fixed.pole.0).hypot(q.1 - fixed.pole.1) / fixed.pole.0.hypot(fixed.pole.1)
        })
        .collect();
    eprintln!("relative distance of the dominant pole at C = 1, 10, 100, 1000 J/K: {d:?}");
    for k in 1..d.len() {
        assert!(d[k] < 0.15 * d[k - 1] && d[k] > 0.05 * d[k - 1], "{d:?}");
    }
    assert!(d[3] < 1e-5, "{d:?}");
}

#[test]
fn finite_capacity_lowers_the_power() {
    let n = 3;
    let fixed = fixed_case(n, "fixed", 8.0).unwrap();
    let cases: Vec<_> = [500.0, 5.0, 0.5]
        .iter()
        .map(|&c| matrix_case(n, c, 8.0).unwrap())
        .collect();
    for c in &cases {
        eprintln!(
            "{}: pole {:?}, {:.3} Hz, strokes {:.2} / {:.2} mm, {:.4} W (fixed wall {:.4} W)",
            c.label,
            c.pole,
            c.frequency_hz,
            1e3 * c.x_stroke,
            1e3 * c.y_stroke,
            c.power_w,
            fixed.power_w
        );
    }
    // a free matrix carries no net heat over a cycle (only its axial conduction): even at
    // 500 J/K the power is below the fixed wall's, by a capacity-independent few percent
    assert!(cases[0].power_w < 0.97 * fixed.power_w);
    assert!(cases[0].power_w > 0.8 * fixed.power_w);
    // smaller capacities lower it further, and the strokes with it
    assert!(cases[1].power_w < cases[0].power_w && cases[2].power_w < 0.95 * cases[1].power_w);
    assert!(cases[2].y_stroke < cases[0].y_stroke);
    // the frequency hardly moves (within 1 %)
    for c in &cases {
        assert!((c.frequency_hz / fixed.frequency_hz - 1.0).abs() < 0.01);
    }
}
