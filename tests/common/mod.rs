//! Shared helpers of the foundation tests: small test models declared with
//! `stirling_model!`, seeded random physical states, and a finite-difference checker.
#![allow(dead_code)]

pub mod models;

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use stirling::dsl::{Model, StateKind};

/// A seeded generator, so that every failure reproduces.
pub fn rng(seed: u64) -> StdRng {
    StdRng::seed_from_u64(seed)
}

/// How the gas pressures of a random state are spread.
#[derive(Clone, Copy, Debug)]
pub enum Spread {
    /// Each pressure within +-5 % of the charge: the upwind switches are saturated.
    Wide,
    /// Each pressure within +-1 Pa of the charge: the links' smooth upwind switches
    /// (width `mdot_eps R_link`, about 0.5 Pa) are in their transition.
    Balanced,
}

/// A random state near equilibrium: positions +-5 mm, velocities +-0.5 m/s, pressures as
/// `spread` says around the charge, masses within +-5 % of the equilibrium `m0`.
pub fn random_state(model: &dyn Model, p: &[f64], spread: Spread, rng: &mut StdRng) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    for (xi, s) in x.iter_mut().zip(model.states()) {
        let u: f64 = rng.gen_range(-1.0..1.0);
        *xi = match s.kind {
            StateKind::Position(_) => 5e-3 * u,
            StateKind::Velocity(_) => 0.5 * u,
            StateKind::Pressure(_) => match spread {
                Spread::Wide => *xi * (1.0 + 0.05 * u),
                Spread::Balanced => *xi + u,
            },
            StateKind::Mass(_) => *xi * (1.0 + 0.05 * u),
        };
    }
    x
}

/// Typical magnitude of each state near equilibrium: the scale of its finite-difference
/// step and of the comparison (`J_ij s_j / s_i` is dimensionless-per-second).
pub fn state_scales(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    model
        .states()
        .iter()
        .zip(&x0)
        .map(|(s, &x0)| match s.kind {
            StateKind::Position(_) => 1e-2,
            StateKind::Velocity(_) => 0.1,
            // well below the 0.5 Pa width of the upwind switch
            StateKind::Pressure(_) => 100.0,
            StateKind::Mass(_) => x0.abs(),
        })
        .collect()
}

/// Central differences of `f` (`m` outputs) around `x`, one column per input, column-major,
/// with Richardson extrapolation over the steps `h_j` and `h_j / 2` (error `O(h^4)`).
pub fn fd_jacobian(f: &dyn Fn(&[f64], &mut [f64]), x: &[f64], m: usize, steps: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; m * x.len()];
    let (mut fp, mut fm) = (vec![0.0; m], vec![0.0; m]);
    let mut xx = x.to_vec();
    let mut central = |j: usize, h: f64, xx: &mut Vec<f64>| -> Vec<f64> {
        xx[j] = x[j] + h;
        f(xx, &mut fp);
        xx[j] = x[j] - h;
        f(xx, &mut fm);
        xx[j] = x[j];
        // the step actually taken, after rounding of x +- h
        let dx = (x[j] + h) - (x[j] - h);
        fp.iter().zip(&fm).map(|(a, b)| (a - b) / dx).collect()
    };
    for j in 0..x.len() {
        let d1 = central(j, steps[j], &mut xx);
        let d2 = central(j, steps[j] / 2.0, &mut xx);
        for i in 0..m {
            out[i + m * j] = (4.0 * d2[i] - d1[i]) / 3.0;
        }
    }
    out
}

/// One disagreement between an analytic and a finite-difference matrix.
#[derive(Debug)]
pub struct Mismatch {
    pub row: String,
    pub col: String,
    pub analytic: f64,
    pub fd: f64,
}

/// Compare column-major `analytic` against `fd` (`m` rows). Both are first scaled by
/// `col_scale_j / row_scale_i`; an entry is significant when either value exceeds
/// `tiny` times its scaled column's maximum, and then must agree to `rel`; entries
/// below that must both be below it (a term the analytic Jacobian drops, or invents,
/// shows up as a mismatch either way).
pub fn compare(
    analytic: &[f64],
    fd: &[f64],
    row_names: &[String],
    col_names: &[String],
    row_scale: &[f64],
    col_scale: &[f64],
    rel: f64,
    tiny: f64,
) -> Vec<Mismatch> {
    let m = row_names.len();
    let mut bad = Vec::new();
    for (j, cs) in col_scale.iter().enumerate() {
        let scaled = |v: f64, i: usize| v * cs / row_scale[i];
        let colmax = (0..m).map(|i| scaled(analytic[i + m * j], i).abs().max(scaled(fd[i + m * j], i).abs())).fold(0.0, f64::max);
        let floor = tiny * colmax;
        for i in 0..m {
            let (a, d) = (analytic[i + m * j], fd[i + m * j]);
            let (sa, sd) = (scaled(a, i).abs(), scaled(d, i).abs());
            let ok = if sa.max(sd) > floor { (a - d).abs() <= rel * a.abs().max(d.abs()) } else { true };
            if !ok || !a.is_finite() {
                bad.push(Mismatch { row: row_names[i].clone(), col: col_names[j].clone(), analytic: a, fd: d });
            }
        }
    }
    bad
}

/// Relative tolerance of the finite-difference checks.
pub const REL: f64 = 1e-6;
/// Entries below this fraction of their (scaled) column's maximum are not compared.
pub const TINY: f64 = 1e-8;

/// Check `jacobian_dense` and `param_jacobian_dense` of `model` against Richardson-extrapolated
/// central differences at `x`; returns the mismatches of both, labelled.
pub fn check_jacobians(model: &dyn Model, p: &[f64], x: &[f64]) -> Vec<Mismatch> {
    let n = model.n_states();
    let names = model.state_names();
    let scales = state_scales(model, p);
    // states
    let f = |xx: &[f64], out: &mut [f64]| model.rhs(p, xx, 0.0, out);
    let steps: Vec<f64> = scales.iter().map(|s| 1e-5 * s).collect();
    let fd = fd_jacobian(&f, x, n, &steps);
    let jac = model.jacobian_dense(p, x, 0.0);
    let mut bad = compare(&jac, &fd, &names, &names, &scales, &scales, REL, TINY);
    // parameters
    let pnames: Vec<String> = model.params().iter().map(|q| format!("param {}", q.name)).collect();
    let g = |pp: &[f64], out: &mut [f64]| model.rhs(pp, x, 0.0, out);
    let pscales: Vec<f64> = p.iter().map(|v| if *v == 0.0 { 1.0 } else { v.abs() }).collect();
    let psteps: Vec<f64> = pscales.iter().map(|s| 1e-5 * s).collect();
    let pfd = fd_jacobian(&g, p, n, &psteps);
    let pjac = model.param_jacobian_dense(p, x, 0.0);
    bad.extend(compare(&pjac, &pfd, &names, &pnames, &scales, &pscales, REL, TINY));
    bad
}

/// Run [`check_jacobians`] at `count` seeded random states of each spread; panic with a
/// readable list if any entry disagrees.
pub fn assert_jacobians(model: &dyn Model, label: &str, seed: u64, count: usize) {
    let p = model.default_params();
    let mut rng = rng(seed);
    let mut report = Vec::new();
    for spread in [Spread::Wide, Spread::Balanced] {
        for k in 0..count {
            let x = random_state(model, &p, spread, &mut rng);
            for b in check_jacobians(model, &p, &x) {
                report.push(format!(
                    "  {spread:?} state {k}: d {}/d {}: analytic {:.12e}, fd {:.12e}, rel err {:.2e}",
                    b.row,
                    b.col,
                    b.analytic,
                    b.fd,
                    (b.analytic - b.fd).abs() / b.analytic.abs().max(b.fd.abs())
                ));
            }
        }
    }
    assert!(report.is_empty(), "{label}: {} Jacobian entries disagree with finite differences:\n{}", report.len(), report.join("\n"));
}
