//! Shared helpers of the foundation tests: small test models declared with
//! `stirling_model!`, seeded random physical states, and a finite-difference checker.
#![allow(dead_code)]

pub mod bond;
pub mod fit;
pub mod models;
pub mod same;
pub mod startup;
pub mod verdict;

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
    /// Pressures a few Pa apart around one common level within +-5 % of the charge: each
    /// differs from the previous one by 0.02 to 1 Pa (log-uniform, one direction, so no two are
    /// closer than 0.02 Pa), so the links' smooth upwind switches (width `mdot_eps R_link`,
    /// 0.01 to 0.5 Pa) are in their transition, while the level stays away from the bounce
    /// pressure (a level equal to it makes entries such as `d v'/d Ar = (Pb - P)/md`
    /// cancellations that finite differences cannot resolve to 1e-6).
    Balanced,
}

/// A random state near equilibrium: positions +-5 mm, velocities +-0.5 m/s, pressures as
/// `spread` says around the charge, masses within +-5 % of the equilibrium `m0`.
pub fn random_state(model: &dyn Model, p: &[f64], spread: Spread, rng: &mut StdRng) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let level = 1.0 + 0.05 * rng.gen_range(-1.0..1.0);
    let direction = if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
    let mut offset = 0.0;
    for (xi, s) in x.iter_mut().zip(model.states()) {
        let u: f64 = rng.gen_range(-1.0..1.0);
        *xi = match s.kind {
            StateKind::Position(_) => 5e-3 * u,
            StateKind::Velocity(_) => 0.5 * u,
            StateKind::Pressure(_) => match spread {
                Spread::Wide => *xi * (1.0 + 0.05 * u),
                Spread::Balanced => {
                    offset += direction * 10f64.powf(rng.gen_range(-1.7..0.0));
                    *xi * level + offset
                }
            },
            StateKind::Mass(_) => *xi * (1.0 + 0.05 * u),
            StateKind::WallTemperature(_) => *xi + 20.0 * u,
        };
    }
    x
}

/// The smallest difference between two gas pressures of `x`.
pub fn min_pressure_gap(model: &dyn Model, x: &[f64]) -> f64 {
    let pressures: Vec<f64> = model
        .states()
        .iter()
        .zip(x)
        .filter(|(s, _)| matches!(s.kind, StateKind::Pressure(_)))
        .map(|(_, &v)| v)
        .collect();
    let mut gap = f64::INFINITY;
    for (i, a) in pressures.iter().enumerate() {
        for b in &pressures[i + 1..] {
            gap = gap.min((a - b).abs());
        }
    }
    gap
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
            StateKind::Pressure(_) => 100.0,
            StateKind::Mass(_) => x0.abs(),
            StateKind::WallTemperature(_) => 10.0,
        })
        .collect()
}

/// Upper finite-difference steps of the states for [`fd_jacobian`]: 1e-3 of the typical
/// magnitude, except the pressures. The smooth upwind switch `tanh(mdot / mdot_eps)` has a
/// width of `mdot_eps R_link` in pressure, 0.01 Pa for the shortest links of the 50-section
/// chain, so pressures start at 1e-3 Pa.
///
/// The quadratic flow law's `mdot(dP)` is only once differentiable at `dP = 0` (it holds
/// `dP |dP|`), so a central difference must not straddle that point either: the pressure
/// step is also at most 5 % of the smallest gap between two pressures of `x`.
///
/// Wall temperatures start at 1 K: they enter the gas rows linearly (`h A (Tw - T)`), whose
/// values reach `|P'| ~ 5e11 Pa/s` at wide pressure spreads on short links (n = 50), so a
/// 0.01 K step leaves a round-off of `eps |P'| / h ~ 5e-3` on `dP'/dTw = (gamma-1) h A / V
/// = 3.77e4`, 1e-6 relative: the size of the tolerance.
pub fn fd_steps(model: &dyn Model, p: &[f64], x: &[f64]) -> Vec<f64> {
    let dp = 1e-3f64.min(0.05 * min_pressure_gap(model, x));
    let states = model.states();
    states
        .iter()
        .zip(state_scales(model, p))
        .map(|(s, scale)| match s.kind {
            StateKind::Pressure(_) => dp,
            StateKind::WallTemperature(_) => 1.0,
            _ => 1e-3 * scale,
        })
        .collect()
}

/// Finite-difference derivatives of `f` (`m` outputs) around `x`, one column per input,
/// column-major: Ridders' method (Numerical Recipes `dfridr`), i.e. central differences at
/// steps `h_j, h_j/1.4, h_j/1.4^2, ..` extrapolated to zero step in a Neville tableau, each
/// output keeping the estimate with the smallest error estimate. `h_j` is an upper step:
/// below the scale on which `f` varies nonlinearly in input `j`, so the tableau converges.
pub fn fd_jacobian(f: &dyn Fn(&[f64], &mut [f64]), x: &[f64], m: usize, steps: &[f64]) -> Vec<f64> {
    ridders(f, x, m, steps, false).0
}

/// As [`fd_jacobian`], starting from each of `starts` (factors of `steps`) and keeping, per
/// entry, the estimate with the smallest error estimate: for parameters, whose scales of
/// nonlinearity range from the parameter itself down to a few percent of it.
pub fn fd_jacobian_multi(
    f: &dyn Fn(&[f64], &mut [f64]),
    x: &[f64],
    m: usize,
    steps: &[f64],
    starts: &[f64],
) -> Vec<f64> {
    let sets: Vec<Vec<f64>> = starts
        .iter()
        .map(|s| steps.iter().map(|h| h * s).collect())
        .collect();
    fd_jacobian_best(f, x, m, &sets, false)
}

/// As [`fd_jacobian`] from each set of upper steps, keeping per entry the estimate with the
/// smallest error estimate. With `roundoff`, an estimate's error estimate is at least the
/// round-off of its smallest central difference, `4 eps max(|f(x+h)|, |f(x-h)|) / 2h`: in a row
/// whose value is large next to the entry, successive central differences can agree exactly
/// (their round-off is quantized), which Ridders' tableau reads as zero error at a step where
/// the round-off is 1e-6 of the entry; the floor makes the larger steps win there.
pub fn fd_jacobian_best(
    f: &dyn Fn(&[f64], &mut [f64]),
    x: &[f64],
    m: usize,
    step_sets: &[Vec<f64>],
    roundoff: bool,
) -> Vec<f64> {
    let mut best: Option<(Vec<f64>, Vec<f64>)> = None;
    for h in step_sets {
        let (est, err) = ridders(f, x, m, h, roundoff);
        best = Some(match best {
            None => (est, err),
            Some((mut be, mut berr)) => {
                for k in 0..be.len() {
                    if err[k] < berr[k] {
                        (be[k], berr[k]) = (est[k], err[k]);
                    }
                }
                (be, berr)
            }
        });
    }
    best.map(|b| b.0).unwrap_or_default()
}

/// Ridders' extrapolation: the estimates and their error estimates, column-major.
fn ridders(
    f: &dyn Fn(&[f64], &mut [f64]),
    x: &[f64],
    m: usize,
    steps: &[f64],
    roundoff: bool,
) -> (Vec<f64>, Vec<f64>) {
    const CON: f64 = 1.4;
    const NTAB: usize = 14;
    const SAFE: f64 = 2.0;
    let mut out = vec![0.0; m * x.len()];
    let mut errs = vec![0.0; m * x.len()];
    let (mut fp, mut fm) = (vec![0.0; m], vec![0.0; m]);
    let mut xx = x.to_vec();
    for j in 0..x.len() {
        // the round-off of the latest central difference, per output
        let mut noise = vec![0.0; m];
        let mut central = |h: f64, noise: &mut Vec<f64>| -> Vec<f64> {
            xx[j] = x[j] + h;
            f(&xx, &mut fp);
            xx[j] = x[j] - h;
            f(&xx, &mut fm);
            xx[j] = x[j];
            // the step actually taken, after rounding of x +- h
            let dx = (x[j] + h) - (x[j] - h);
            if roundoff {
                for r in 0..m {
                    noise[r] = 4.0 * f64::EPSILON * fp[r].abs().max(fm[r].abs()) / dx;
                }
            }
            fp.iter().zip(&fm).map(|(a, b)| (a - b) / dx).collect()
        };
        let mut h = steps[j];
        // tableau[k][i]: extrapolation order k at step level i, one value per output
        let mut tab: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); NTAB]; NTAB];
        tab[0][0] = central(h, &mut noise);
        let mut best = tab[0][0].clone();
        let mut err = vec![f64::INFINITY; m];
        let mut done = vec![false; m];
        for i in 1..NTAB {
            h /= CON;
            tab[0][i] = central(h, &mut noise);
            let mut fac = CON * CON;
            for k in 1..=i {
                tab[k][i] = (0..m)
                    .map(|r| (tab[k - 1][i][r] * fac - tab[k - 1][i - 1][r]) / (fac - 1.0))
                    .collect();
                fac *= CON * CON;
                for r in (0..m).filter(|&r| !done[r]) {
                    let e = (tab[k][i][r] - tab[k - 1][i][r])
                        .abs()
                        .max((tab[k][i][r] - tab[k - 1][i - 1][r]).abs())
                        .max(noise[r]);
                    if e <= err[r] {
                        err[r] = e;
                        best[r] = tab[k][i][r];
                    }
                }
            }
            // a higher order that got worse by a significant factor: stop early
            for r in 0..m {
                if (tab[i][i][r] - tab[i - 1][i - 1][r]).abs() >= SAFE * err[r] {
                    done[r] = true;
                }
            }
            if done.iter().all(|&d| d) {
                break;
            }
        }
        for r in 0..m {
            out[r + m * j] = best[r];
            errs[r + m * j] = err[r];
        }
    }
    (out, errs)
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
/// `tiny` times the larger of its scaled column's and row's maximum (the row's for a column
/// that is zero, such as a parameter the rows do not depend on), and then must agree to
/// `rel`. A term the analytic Jacobian drops, or invents, is significant on one side, so
/// it shows up as a mismatch either way.
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
    let scaled = |k: usize, i: usize, j: usize| {
        let s = col_scale[j] / row_scale[i];
        (analytic[k] * s).abs().max((fd[k] * s).abs())
    };
    let mut colmax = vec![0.0f64; col_scale.len()];
    let mut rowmax = vec![0.0f64; m];
    for j in 0..col_scale.len() {
        for i in 0..m {
            let v = scaled(i + m * j, i, j);
            colmax[j] = colmax[j].max(v);
            rowmax[i] = rowmax[i].max(v);
        }
    }
    for j in 0..col_scale.len() {
        let scaled = |v: f64, i: usize| v * col_scale[j] / row_scale[i];
        for i in 0..m {
            let floor = tiny * colmax[j].max(rowmax[i]);
            let (a, d) = (analytic[i + m * j], fd[i + m * j]);
            let (sa, sd) = (scaled(a, i).abs(), scaled(d, i).abs());
            let ok = if sa.max(sd) > floor {
                (a - d).abs() <= rel * a.abs().max(d.abs())
            } else {
                true
            };
            if !ok || !a.is_finite() {
                bad.push(Mismatch {
                    row: row_names[i].clone(),
                    col: col_names[j].clone(),
                    analytic: a,
                    fd: d,
                });
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
    check_jacobians_from(model, p, x, &[1.0], REL)
}

/// As [`check_jacobians`], differencing the state columns other than pressures from each of
/// the upper steps `starts` times [`fd_steps`] and keeping per entry the estimate with the
/// smallest error estimate, and comparing to `rel`. Large steps matter in rows whose value is
/// large next to their entry: at wide pressure spreads a regenerator row reaches `|P'| ~ 5e8
/// Pa/s` while `dP'/dx` (through another CV's temperature in an upwind enthalpy) is ~ 300 Pa/(s
/// m), so a central difference at the default 1e-5 m step carries a round-off of `eps |P'| /
/// h ~ 1e-2`, 4e-5 of the entry, which Ridders' tableau cannot remove; these rows are smooth
/// in the positions on the scale of a volume over an area (centimetres), so upper steps 10 and
/// 100 times larger resolve them.
pub fn check_jacobians_from(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    starts: &[f64],
    rel: f64,
) -> Vec<Mismatch> {
    let n = model.n_states();
    let names = model.state_names();
    let scales = state_scales(model, p);
    // states
    let f = |xx: &[f64], out: &mut [f64]| model.rhs(p, xx, 0.0, out);
    let base = fd_steps(model, p, x);
    let jac = model.jacobian_dense(p, x, 0.0);
    let states = model.states();
    let is_p = |k: usize| matches!(states[k].kind, StateKind::Pressure(_));
    // a pressure's step stays below 5 % of its gap to every pressure whose row it enters (the
    // pressures it is linked to), so that no central difference straddles a flow law's kink
    let cap: Vec<f64> = (0..n)
        .map(|j| {
            let near = (0..n)
                .filter(|&k| k != j && is_p(k) && jac[k + n * j] != 0.0)
                .map(|k| (x[j] - x[k]).abs())
                .fold(f64::INFINITY, f64::min);
            0.05 * near
        })
        .collect();
    let sets: Vec<Vec<f64>> = starts
        .iter()
        .map(|&s| {
            (0..n)
                .map(|j| match states[j].kind {
                    _ if s == 1.0 => base[j],
                    StateKind::Pressure(_) => (base[j] * s).min(cap[j]).max(base[j]),
                    _ => base[j] * s,
                })
                .collect()
        })
        .collect();
    let fd = fd_jacobian_best(&f, x, n, &sets, starts.len() > 1);
    let mut bad = compare(&jac, &fd, &names, &names, &scales, &scales, rel, TINY);
    // parameters
    let pnames: Vec<String> = model
        .params()
        .iter()
        .map(|q| format!("param {}", q.name))
        .collect();
    let g = |pp: &[f64], out: &mut [f64]| model.rhs(pp, x, 0.0, out);
    let pscales: Vec<f64> = p
        .iter()
        .map(|v| if *v == 0.0 { 1.0 } else { v.abs() })
        .collect();
    // a per-section leak's upwind switch is 1 % of the bounce pressure wide (`mdot_eps n / Gl`):
    // start below it too; the small starts need the round-off floor of the error estimate (a
    // start of 1e-3 of `mdot_eps` on a row of 1e7 Pa/s otherwise wins with a spurious zero
    // error estimate and misses by 1e-6)
    let psets: Vec<Vec<f64>> = [0.5, 0.1, 0.01, 0.001]
        .iter()
        .map(|s| pscales.iter().map(|h| h * s).collect())
        .collect();
    let pfd = fd_jacobian_best(&g, p, n, &psets, true);
    let pjac = model.param_jacobian_dense(p, x, 0.0);
    bad.extend(compare(
        &pjac, &pfd, &names, &pnames, &scales, &pscales, rel, TINY,
    ));
    bad
}

/// The largest relative disagreement over the significant entries of both Jacobians at `x`
/// (as [`check_jacobians_from`] compares them), with its entry.
pub fn worst_jacobian_error(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    starts: &[f64],
) -> (f64, String) {
    let mut worst = (0.0, String::new());
    for b in check_jacobians_from(model, p, x, starts, 0.0) {
        let e = (b.analytic - b.fd).abs() / b.analytic.abs().max(b.fd.abs());
        if e > worst.0 {
            worst = (e, format!("d {}/d {}", b.row, b.col));
        }
    }
    worst
}

/// The finite-difference check of a model whose every section links to one closed CV (an
/// arrow-shaped Jacobian) at one state: the sections' entries in that CV's pressure and mass
/// columns are below finite-difference resolution and skipped (the tests check them against a
/// hand derivation); at n >= 50 the `mdot_eps` column is held to 1e-5 (the chains' upwind
/// switches make it curve on 1 % of `mdot_eps`), every other entry to [`REL`]. Disagreements
/// are appended to `report` under `label`; returns the worst relative error.
pub fn arrow_fd_errors(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    starts: &[f64],
    label: &str,
    report: &mut Vec<String>,
) -> f64 {
    let mut worst = 0.0f64;
    for b in check_jacobians_from(model, p, x, starts, 0.0) {
        if (b.col == "P_bounce" || b.col == "m_bounce") && b.row.contains("_r[") {
            continue;
        }
        let rel = (b.analytic - b.fd).abs() / b.analytic.abs().max(b.fd.abs());
        worst = worst.max(rel);
        let tol = if model.n() >= 50 && b.col == "param mdot_eps" {
            1e-5
        } else {
            REL
        };
        if rel > tol {
            report.push(format!(
                "{label}: d {}/d {}: {:e} vs {:e} ({rel:.1e})",
                b.row, b.col, b.analytic, b.fd
            ));
        }
    }
    worst
}

/// Run [`check_jacobians`] at `count` seeded random states of each spread; panic with a
/// readable list if any entry disagrees.
pub fn assert_jacobians(model: &dyn Model, label: &str, seed: u64, count: usize) {
    assert_jacobians_at(model, label, seed, count, &[Spread::Wide, Spread::Balanced]);
}

/// As [`assert_jacobians`], at the given spreads only.
pub fn assert_jacobians_at(
    model: &dyn Model,
    label: &str,
    seed: u64,
    count: usize,
    spreads: &[Spread],
) {
    let p = model.default_params();
    let mut rng = rng(seed);
    let mut report = Vec::new();
    for &spread in spreads {
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
    assert!(
        report.is_empty(),
        "{label}: {} Jacobian entries disagree with finite differences:\n{}",
        report.len(),
        report.join("\n")
    );
}

/// The energy budget of docs/physics.md section 10 at one state: `(dE/dt, heat + boundary +
/// mechanical, round-off scale)`. `E` (gas `P V/(gamma-1)` with `V` affine in the positions,
/// kinetic, spring and wall `C Tw` energies) is a quadratic polynomial of the states, so the
/// central difference along the right-hand side is exact up to round-off, whose scale is
/// `E/h + sum |P_i' V_i|`: the internal enthalpy flows cancel in the sum, and at wide pressure
/// spreads on short links they reach 1e5 W per section against a budget of 100 W.
pub fn energy_rate(model: &dyn Model, p: &[f64], x: &[f64]) -> (f64, f64, f64) {
    let n = model.n_states();
    let mut f = vec![0.0; n];
    model.rhs(p, x, 0.0, &mut f);
    let h = 1e-3;
    let at = |s: f64| -> Vec<f64> { x.iter().zip(&f).map(|(xi, fi)| xi + s * fi).collect() };
    let de = (model.energy(p, &at(h)) - model.energy(p, &at(-h))) / (2.0 * h);
    let w = model.power(p, x);
    let names = model.vessel_names();
    let (mut pr, mut vol) = (vec![0.0; names.len()], vec![0.0; names.len()]);
    model.pv(p, x, &mut pr, &mut vol);
    let flows: f64 = model
        .states()
        .iter()
        .zip(&f)
        .filter_map(|(s, fi)| match s.kind {
            StateKind::Pressure(k) => Some((fi * vol[k]).abs()),
            _ => None,
        })
        .sum();
    let scale = model.energy(p, x).abs() / h + flows;
    (de, w.heat + w.boundary + w.mechanical, scale)
}

/// `(sum m_i', sum |m_i'|)` over the mass states: the closed gas's mass rate, which must
/// vanish to the round-off of the sum (`eps sum |m_i'|`).
pub fn mass_rate(model: &dyn Model, p: &[f64], x: &[f64]) -> (f64, f64) {
    let mut f = vec![0.0; model.n_states()];
    model.rhs(p, x, 0.0, &mut f);
    let masses = model.states().into_iter().zip(f);
    let rates: Vec<f64> = masses
        .filter(|(s, _)| matches!(s.kind, StateKind::Mass(_)))
        .map(|(_, r)| r)
        .collect();
    (rates.iter().sum(), rates.iter().map(|r| r.abs()).sum())
}
