//! `schmidt` on the default engine reproduces docs/physics.md section 8 (the seed's Figure 8), and
//! its margins agree with an independent computation written here.

use stirling::dsl::{Closure, Model};
use stirling::models::linear::nalgebra::{Complex, DMatrix, DVector};
use stirling::models::linear::{self, Channel, LinearOptions, Linearization};

fn schmidt() -> (Box<dyn Model>, Vec<f64>, Linearization) {
    let model = stirling::models::build("schmidt", None, Closure::Full).unwrap();
    let p = model.default_params();
    let lin = linear::linearize(model.as_ref(), &p, &LinearOptions::default()).unwrap();
    (model, p, lin)
}

fn assert_poles(got: &[linear::Pole], want: &[(f64, f64)], tol: f64) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.re - w.0).abs() < tol && (g.im - w.1).abs() < tol,
            "pole {} {:+}j, expected {} {:+}j",
            g.re,
            g.im,
            w.0,
            w.1
        );
    }
}

#[test]
fn closed_and_open_loop_poles() {
    let (_, _, lin) = schmidt();
    let want = [
        (9.6225, 89.5373),
        (9.6225, -89.5373),
        (-25.1879, 94.1366),
        (-25.1879, -94.1366),
    ];
    assert_poles(&lin.dynamics.poles, &want, 1e-3);
    assert!(lin.dynamics.poles[0].rhp && lin.dynamics.poles[1].rhp && !lin.dynamics.poles[2].rhp);
    assert!((lin.dynamics.poles[0].freq_hz - 89.5373 / (2.0 * std::f64::consts::PI)).abs() < 1e-3);
    let ol = [
        (-3.5631, 88.8583),
        (-3.5631, -88.8583),
        (-12.0023, 6.3431),
        (-12.0023, -6.3431),
    ];
    assert_poles(&lin.open_loop.poles, &ol, 1e-3);
    assert!(lin.dynamics.reduction.inventory.is_none());
    assert!(lin.dynamics.equilibrium.residual < 1e-6);
}

#[test]
fn the_default_channel_is_the_common_pressure() {
    let (model, p, lin) = schmidt();
    assert_eq!(lin.open_loop.full.channel, Channel::Pressure);
    let get = |n: &str| p[model.param_index(n).unwrap()];
    let (a, ar, md, mp) = (get("A"), get("Ar"), get("md"), get("mp"));
    let want = [0.0, -ar / md, 0.0, -(a - ar) / mp];
    for (b, w) in lin.open_loop.full.b.iter().zip(want) {
        assert!(
            (b - w).abs() <= 1e-7 * w.abs().max(1e-9),
            "B = {:?}, expected {want:?}",
            lin.open_loop.full.b
        );
    }
    // u = P - Pmean: C = grad P = [C1 A - C2 (A - Ar), 0, C2 (A - Ar), 0] (report: -562751, 1.2059e6)
    let c = &lin.open_loop.full.c;
    assert!(
        (c[0] / -562751.0 - 1.0).abs() < 1e-5 && (c[2] / 1.2059e6 - 1.0).abs() < 1e-4,
        "C = {c:?}"
    );
}

#[test]
fn margins_reproduce_figure_8() {
    let (_, _, lin) = schmidt();
    let m = &lin.margins;
    assert!((m.gain_db.unwrap() + 6.630).abs() < 0.01, "{m:?}");
    assert!(
        (m.phase_crossover_rad_s.unwrap() - 81.60).abs() < 0.01,
        "{m:?}"
    );
    assert!((m.phase_deg.unwrap() + 79.50).abs() < 0.05, "{m:?}");
    assert!(
        (m.gain_crossover_rad_s.unwrap() - 91.30).abs() < 0.01,
        "{m:?}"
    );
    // All crossovers: phase crosses -180 deg twice (81.60, 97.79), |L| = 1 once.
    assert_eq!(m.all_gain.len(), 2, "{m:?}");
    assert!(
        (m.all_gain[1].gain_db - 9.764).abs() < 0.01
            && (m.all_gain[1].phase_crossover_rad_s - 97.79).abs() < 0.01
    );
    assert_eq!(m.all_phase.len(), 1, "{m:?}");
}

/// `L(jw) = K (jwI - A0)^-1 B` by a dense complex LU, independent of the Hessenberg evaluator.
fn l_dense(a: &DMatrix<f64>, b: &DVector<f64>, k: &DVector<f64>, w: f64) -> Complex<f64> {
    let n = a.nrows();
    let s = Complex::new(0.0, w);
    let m = DMatrix::from_fn(
        n,
        n,
        |i, j| if i == j { s } else { Complex::new(0.0, 0.0) } - a[(i, j)],
    );
    let z = m.lu().solve(&b.map(|v| Complex::new(v, 0.0))).unwrap();
    z.iter().zip(k.iter()).map(|(z, k)| z * k).sum()
}

fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let flo = f(lo);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if (f(mid) > 0.0) == (flo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn margins_agree_with_a_dense_sweep() {
    let (_, _, lin) = schmidt();
    let ol = &lin.open_loop.full;
    let k = ol.k();
    let l = |w: f64| l_dense(&ol.a, &ol.b, &k, w);
    let (mut gains, mut phases) = (Vec::new(), Vec::new());
    let ws: Vec<f64> = (1..=200_000).map(|i| i as f64 * 0.01).collect();
    for pair in ws.windows(2) {
        let (l0, l1) = (l(pair[0]), l(pair[1]));
        if (l0.im > 0.0) != (l1.im > 0.0) {
            let w = bisect(|w| l(w).im, pair[0], pair[1]);
            if l(w).re < 0.0 {
                gains.push((w, -20.0 * l(w).norm().log10()));
            }
        }
        if (l0.norm() > 1.0) != (l1.norm() > 1.0) {
            let w = bisect(|w| l(w).norm() - 1.0, pair[0], pair[1]);
            let mut pm: f64 = 180.0 + l(w).arg().to_degrees();
            pm -= 360.0 * (pm / 360.0).round();
            phases.push((w, pm));
        }
    }
    let m = &lin.margins;
    assert_eq!(gains.len(), m.all_gain.len(), "sweep {gains:?} vs {m:?}");
    for (g, mg) in gains.iter().zip(&m.all_gain) {
        assert!(
            (g.0 - mg.phase_crossover_rad_s).abs() < 1e-6 && (g.1 - mg.gain_db).abs() < 1e-6,
            "{g:?} vs {mg:?}"
        );
    }
    assert_eq!(phases.len(), m.all_phase.len(), "sweep {phases:?} vs {m:?}");
    for (p, mp) in phases.iter().zip(&m.all_phase) {
        assert!(
            (p.0 - mp.gain_crossover_rad_s).abs() < 1e-6 && (p.1 - mp.phase_deg).abs() < 1e-6,
            "{p:?} vs {mp:?}"
        );
    }
    // Closing the loop gives back the Jacobian: eig(A0 - B K) = the closed-loop poles.
    let acl = &ol.a - &ol.b * k.transpose();
    assert!((acl - &lin.dynamics.jacobian).amax() < 1e-9 * lin.dynamics.jacobian.amax());
}
