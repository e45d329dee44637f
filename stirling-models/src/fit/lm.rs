//! A small Levenberg-Marquardt (Marquardt's diagonal scaling, Nielsen's damping update).
//!
//! Why not a crate: `levenberg-marquardt` (rust-cv, the maintained one) is built on nalgebra
//! 0.33/0.34 while the workspace pins 0.35 (diffsol's), so it would pull a second nalgebra and
//! convert at the boundary; and our residuals and Jacobians come together from one
//! sensitivity integration that can fail (a nonphysical trial), which its trait cannot report.

use nalgebra::{DMatrix, DVector};

/// Residuals and their Jacobian (rows: residuals, columns: variables); `None` when the
/// trial point cannot be evaluated (the step is then rejected).
pub type Eval<'a> = dyn FnMut(&[f64]) -> Option<(Vec<f64>, DMatrix<f64>)> + 'a;

/// Options.
#[derive(Clone, Copy, Debug)]
pub struct LmOptions {
    pub max_iter: usize,
    /// Stop when the relative decrease of the cost is below this.
    pub ftol: f64,
    /// Stop when the decrease of the cost is below this (absolute; 0: off). For residuals
    /// of unit variance the cost is half a chi-square: a decrease far below 1 changes no
    /// test or interval the fit feeds.
    pub fatol: f64,
    /// Stop when the step is below this (in the variables' units).
    pub xtol: f64,
    pub lambda0: f64,
    /// Largest step (max norm, in the variables' units); longer steps are shortened.
    pub max_step: f64,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iter: 50,
            ftol: 1e-10,
            fatol: 0.0,
            xtol: 1e-9,
            lambda0: 1e-3,
            max_step: f64::INFINITY,
        }
    }
}

impl LmOptions {
    /// The stages' and the multiple shooting's settings: 30 iterations, a relative cost
    /// decrease of 1e-8 and a step of 1e-7 (scaled variables) to stop.
    pub fn stage() -> Self {
        Self {
            max_iter: 30,
            ftol: 1e-8,
            xtol: 1e-7,
            ..Self::default()
        }
    }
}

/// The result.
#[derive(Clone, Debug)]
pub struct LmResult {
    pub x: Vec<f64>,
    pub residuals: Vec<f64>,
    pub jacobian: DMatrix<f64>,
    /// `sum r^2 / 2`.
    pub cost: f64,
    pub iterations: usize,
    pub evaluations: usize,
    pub converged: bool,
}

/// The Levenberg-Marquardt step `-(J^T J + lambda diag(J^T J))^-1 g`, shortened to
/// `max_step` (largest component); `None` when the damped matrix is not positive definite.
fn damped_step(
    jtj: &DMatrix<f64>,
    g: &DVector<f64>,
    lambda: f64,
    max_step: f64,
) -> Option<DVector<f64>> {
    let mut a = jtj.clone();
    for i in 0..a.nrows() {
        a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
    }
    let ch = a.cholesky()?;
    let mut step = ch.solve(&(-g));
    let long = step.amax();
    if long > max_step {
        step *= max_step / long;
    }
    Some(step)
}

/// Residuals alone at a trial point (no Jacobian); `None` when it cannot be evaluated.
pub type Resid<'a> = dyn FnMut(&[f64]) -> Option<Vec<f64>> + 'a;

/// Minimize `|r(x)|^2 / 2` from `x0`.
pub fn minimize(eval: &mut Eval, x0: &[f64], opts: &LmOptions) -> Option<LmResult> {
    minimize_split(eval, None, x0, opts)
}

/// The current point of the iteration.
struct Point {
    x: Vec<f64>,
    r: Vec<f64>,
    jm: DMatrix<f64>,
    c: f64,
    /// The cost the trials are compared with: with split trials the trial evaluation's own
    /// cost at this point (the two evaluations differ by integration error, ~1e-3 of the
    /// cost on the stages, far above `ftol`: a trial must race a trial), else `c`.
    ct: f64,
}

fn cost(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum::<f64>() / 2.0
}

/// The trial point `xn`: `(residuals, Jacobian)` when its cost is below `c`. With `resid`, the
/// trial is tested on its residuals alone and the Jacobian computed only when it is accepted.
fn try_point(
    eval: &mut Eval,
    resid: &mut Option<&mut Resid>,
    xn: &[f64],
    c: f64,
    evals: &mut usize,
) -> Option<(Vec<f64>, DMatrix<f64>, f64)> {
    *evals += 1;
    if let Some(res) = resid.as_mut() {
        let cn = cost(&res(xn)?);
        if cn >= c {
            return None;
        }
        let (rn, jn) = eval(xn)?;
        return Some((rn, jn, cn));
    }
    let (rn, jn) = eval(xn)?;
    let cn = cost(&rn);
    (cn < c).then_some((rn, jn, cn))
}

/// [`minimize`], with the trial points tested by `resid` (residuals alone, cheaper than
/// `eval`) when given: `eval` then runs only at the start and at accepted points.
pub fn minimize_split(
    eval: &mut Eval,
    mut resid: Option<&mut Resid>,
    x0: &[f64],
    opts: &LmOptions,
) -> Option<LmResult> {
    let (r, jm) = eval(x0)?;
    let c = cost(&r);
    let mut evals = 1;
    let ct = match resid.as_mut() {
        Some(res) => {
            evals += 1;
            res(x0).map_or(c, |rt| cost(&rt))
        }
        None => c,
    };
    let mut pt = Point {
        x: x0.to_vec(),
        c,
        ct,
        r,
        jm,
    };
    let (mut lambda, mut nu) = (opts.lambda0, 2.0);
    let mut converged = false;
    let mut it = 0;
    while it < opts.max_iter {
        it += 1;
        let jtj = pt.jm.transpose() * &pt.jm;
        let g = pt.jm.transpose() * DVector::from_column_slice(&pt.r);
        let mut accepted = false;
        for _ in 0..30 {
            let Some(step) = damped_step(&jtj, &g, lambda, opts.max_step) else {
                lambda *= nu;
                nu *= 2.0;
                continue;
            };
            let xn: Vec<f64> = pt.x.iter().zip(step.iter()).map(|(a, b)| a + b).collect();
            let pred = -(step.dot(&g) + 0.5 * (step.transpose() * &jtj * &step)[(0, 0)]);
            if let Some((rn, jn, cn)) = try_point(eval, &mut resid, &xn, pt.ct, &mut evals) {
                let rho = if pred > 0.0 { (pt.ct - cn) / pred } else { 1.0 };
                lambda *= (1.0f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
                nu = 2.0;
                converged = step.amax() < opts.xtol
                    || (pt.ct - cn) < opts.ftol * pt.ct
                    || (pt.ct - cn) < opts.fatol;
                pt = Point {
                    x: xn,
                    c: cost(&rn),
                    ct: cn,
                    r: rn,
                    jm: jn,
                };
                accepted = true;
                break;
            }
            if step.amax() < opts.xtol {
                // rejected below the step tolerance: the further damped steps are shorter
                // still, and one accepted would stop the fit as converged anyway, less than
                // `xtol` away (they were most of a fit's trials, each a whole run)
                break;
            }
            lambda *= nu;
            nu *= 2.0;
        }
        if !accepted {
            // no decrease possible along any damped step: at a minimum to working precision
            converged = true;
            break;
        }
        if converged {
            break;
        }
    }
    Some(LmResult {
        x: pt.x,
        residuals: pt.r,
        jacobian: pt.jm,
        cost: pt.c,
        iterations: it,
        evaluations: evals,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential() {
        // y = a exp(b t), a = 2, b = -1.5
        let t: Vec<f64> = (0..40).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 2.0 * (-1.5 * t).exp()).collect();
        let mut f = |p: &[f64]| {
            let r: Vec<f64> = t
                .iter()
                .zip(&y)
                .map(|(t, y)| p[0] * (p[1] * t).exp() - y)
                .collect();
            let j = DMatrix::from_fn(t.len(), 2, |i, k| {
                if k == 0 {
                    (p[1] * t[i]).exp()
                } else {
                    p[0] * t[i] * (p[1] * t[i]).exp()
                }
            });
            Some((r, j))
        };
        let res = minimize(&mut f, &[1.0, -0.5], &LmOptions::default()).unwrap();
        assert!(
            (res.x[0] - 2.0).abs() < 1e-8 && (res.x[1] + 1.5).abs() < 1e-8,
            "{:?}",
            res.x
        );
    }

    /// Rosenbrock's residuals and their Jacobian, and options that let it converge.
    fn rosen_r(p: &[f64]) -> Vec<f64> {
        vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]]
    }

    fn rosen_j(p: &[f64]) -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 2, &[-20.0 * p[0], 10.0, -1.0, 0.0])
    }

    fn long_opts() -> LmOptions {
        LmOptions {
            max_iter: 200,
            ..Default::default()
        }
    }

    /// Trial points tested on their residuals alone: the same path and optimum as
    /// [`minimize`], with the Jacobian evaluated only at the start and at accepted points.
    #[test]
    fn split_trials_follow_the_same_path() {
        let (r, j, opts) = (rosen_r, rosen_j, long_opts());
        let mut full = |p: &[f64]| Some((r(p), j(p)));
        let plain = minimize(&mut full, &[-1.2, 1.0], &opts).unwrap();
        let mut jac_calls = 0;
        let mut counted = |p: &[f64]| {
            jac_calls += 1;
            Some((r(p), j(p)))
        };
        let mut resid = |p: &[f64]| Some(r(p));
        let split = minimize_split(&mut counted, Some(&mut resid), &[-1.2, 1.0], &opts).unwrap();
        assert_eq!(plain.x, split.x);
        assert_eq!(plain.iterations, split.iterations);
        // one more: the trial cost at the start
        assert_eq!(plain.evaluations + 1, split.evaluations);
        // the start and one per accepted iteration, not one per trial
        assert!(jac_calls <= split.iterations + 1, "{jac_calls}");
        assert!(jac_calls < split.evaluations, "{jac_calls}");
    }

    /// Trial residuals that differ from the full evaluation's (a cheaper integration's own
    /// error, here 10 % on every residual): trials are compared with trials, so the path and
    /// the optimum are those of the trial cost, not cut short where a decrease is smaller
    /// than the difference of the two evaluations.
    #[test]
    fn split_trials_race_trials_not_the_full_cost() {
        let (r, j, opts) = (rosen_r, rosen_j, long_opts());
        let mut full = |p: &[f64]| Some((r(p), j(p)));
        let plain = minimize(&mut full, &[-1.2, 1.0], &opts).unwrap();
        let mut resid = |p: &[f64]| Some(r(p).iter().map(|v| 1.1 * v).collect());
        let split = minimize_split(&mut full, Some(&mut resid), &[-1.2, 1.0], &opts).unwrap();
        assert!(split.converged);
        assert_eq!(plain.iterations, split.iterations);
        assert!((split.x[0] - 1.0).abs() < 1e-6 && (split.x[1] - 1.0).abs() < 1e-6);
    }

    /// The absolute tolerance stops the iteration at the first accepted step that gains
    /// less than it, well before the relative one would.
    #[test]
    fn absolute_tolerance_stops_early() {
        let mut f = |p: &[f64]| Some((rosen_r(p), rosen_j(p)));
        let full = minimize(&mut f, &[-1.2, 1.0], &long_opts()).unwrap();
        let loose = LmOptions {
            fatol: 1e-3,
            ..long_opts()
        };
        let early = minimize(&mut f, &[-1.2, 1.0], &loose).unwrap();
        assert!(early.converged);
        assert!(
            early.iterations < full.iterations,
            "{} {}",
            early.iterations,
            full.iterations
        );
        assert!(
            early.cost < 1e-2 && early.cost >= full.cost,
            "{} {}",
            early.cost,
            full.cost
        );
    }

    #[test]
    fn rosenbrock() {
        let mut f = |p: &[f64]| Some((rosen_r(p), rosen_j(p)));
        let res = minimize(&mut f, &[-1.2, 1.0], &long_opts()).unwrap();
        assert!(
            (res.x[0] - 1.0).abs() < 1e-6 && (res.x[1] - 1.0).abs() < 1e-6,
            "{:?}",
            res.x
        );
    }
}
