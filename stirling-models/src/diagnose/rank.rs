//! Fit the promising effects jointly with the nominal parameters on the training block and
//! rank them by held-out error with a BIC penalty for the added parameters.
//!
//! A candidate's strength `theta` is fitted by Newton steps on the profiled cost `S(theta)`
//! (the nominal parameters re-fitted by the two-stage identification at every evaluation):
//! a least-squares quadratic through the evaluated points nearest the current best, a step to
//! its minimizer (kept non-negative for bounded strengths and inside a trust region), repeated
//! `newton_iters` times. Intervals come from the curvature, `cov = 2 s^2 H^-1`.
//! The ranking criterion is the held-out BIC change
//! `N_h ln(err_effect / err_nominal) + k ln N_h` (negative: better than the nominal model).

use super::score::{Quad, Screen};
use super::{chi2_sf, DiagnoseOptions, EffectEstimate, Eval, Profile, RankEntry};

fn nearest<'a>(points: &'a [Eval], center: &[f64], scale: &[f64], m: usize) -> Vec<&'a Eval> {
    let mut v: Vec<&Eval> = points.iter().collect();
    let d = |e: &Eval| {
        e.theta
            .iter()
            .zip(center)
            .zip(scale)
            .map(|((a, b), s)| ((a - b) / s).powi(2))
            .sum::<f64>()
    };
    v.sort_by(|a, b| d(a).total_cmp(&d(b)));
    v.truncate(m);
    v
}

/// Fit one screened effect; sets `sc.best_fit` and returns the estimates.
pub fn fit_effect(
    prof: &Profile,
    sc: &mut Screen,
    iters: usize,
    n_free: usize,
) -> Result<Vec<EffectEstimate>, String> {
    let k = sc.step.len();
    let nc = 1 + k + k * (k + 1) / 2;
    for _ in 0..iters {
        let best = sc
            .points
            .iter()
            .min_by(|a, b| a.s_train.total_cmp(&b.s_train))
            .expect("null point")
            .clone();
        let scale: Vec<f64> = sc
            .step
            .iter()
            .zip(&best.theta)
            .map(|(h, t)| h.max(0.5 * t.abs()))
            .collect();
        let pts = nearest(&sc.points, &best.theta, &scale, nc + 1);
        let Some(q) = Quad::fit(&pts, &best.theta, &scale) else {
            break;
        };
        let step: Vec<f64> = match q.newton() {
            Some(s) => s.iter().map(|v| -v).collect(),
            // not convex here: a gradient step of one design scale
            None => {
                let gn =
                    q.g.iter()
                        .zip(&scale)
                        .map(|(g, s)| (g * s).powi(2))
                        .sum::<f64>()
                        .sqrt()
                        .max(1e-300);
                q.g.iter()
                    .zip(&scale)
                    .map(|(g, s)| -g * s * s / gn)
                    .collect()
            }
        };
        let mut th: Vec<f64> = best
            .theta
            .iter()
            .zip(&step)
            .zip(&scale)
            .map(|((t, d), s)| t + d.clamp(-4.0 * s, 4.0 * s))
            .collect();
        for (i, b) in sc.bounded.iter().enumerate() {
            if *b {
                th[i] = th[i].max(0.0);
            }
        }
        if th
            .iter()
            .zip(&best.theta)
            .zip(&scale)
            .all(|((a, b), s)| (a - b).abs() < 0.02 * s)
        {
            break;
        }
        match prof.eval(Some(sc.effect), &th, &best.p) {
            Ok(ev) => sc.points.push(ev),
            Err(_) => break,
        }
    }
    let best = sc
        .points
        .iter()
        .min_by(|a, b| a.s_train.total_cmp(&b.s_train))
        .expect("null point")
        .clone();
    let scale: Vec<f64> = sc
        .step
        .iter()
        .zip(&best.theta)
        .map(|(h, t)| h.max(0.5 * t.abs()))
        .collect();
    let pts = nearest(&sc.points, &best.theta, &scale, nc + 1);
    let s2 = best.s_train / (best.n_train.saturating_sub(n_free + k)).max(1) as f64;
    let cov = Quad::fit(&pts, &best.theta, &scale).and_then(|q| {
        let h = nalgebra::DMatrix::from_fn(k, k, |a, b| q.h[a][b]);
        h.try_inverse().map(|inv| inv * (2.0 * s2))
    });
    let qs = Profile::strengths(sc.effect);
    let est = qs
        .iter()
        .enumerate()
        .map(|(i, q)| {
            let se = cov
                .as_ref()
                .map(|c| c[(i, i)])
                .filter(|v| *v > 0.0)
                .map(f64::sqrt)
                .unwrap_or(f64::NAN);
            let v = best.theta[i];
            EffectEstimate {
                name: q.name.into(),
                value: v,
                std_error: se,
                ci_low: v - 1.96 * se,
                ci_high: v + 1.96 * se,
                unit: q.unit.into(),
            }
        })
        .collect();
    sc.best_fit = Some(best);
    Ok(est)
}

/// Fit the promising candidates and rank every candidate (fitted ones first, by held-out BIC
/// change; then the rest by p-value).
pub fn rank(
    prof: &Profile,
    screens: &[Screen],
    nominal: &Eval,
    n_free: usize,
    opts: &DiagnoseOptions,
) -> (Vec<RankEntry>, Vec<Screen>) {
    let mut screens: Vec<Screen> = screens.to_vec();
    let m = screens.len().max(1) as f64;
    // candidates whose screen was inconclusive (profile not convex) are fitted first, then by score
    let key = |s: &Screen| {
        if s.stat.is_finite() {
            s.stat
        } else {
            f64::INFINITY
        }
    };
    let mut order: Vec<usize> = (0..screens.len())
        .filter(|&i| !screens[i].points.is_empty())
        .collect();
    order.sort_by(|&a, &b| key(&screens[b]).total_cmp(&key(&screens[a])));
    let fit_set: Vec<usize> = order
        .iter()
        .copied()
        .enumerate()
        .filter(|(r, i)| *r < opts.max_fit || screens[*i].p_value < opts.alpha / m)
        .map(|(_, i)| i)
        .collect();
    let n_h = ((prof.hold_idx.1 - prof.hold_idx.0) * nominal.channels.len()) as f64;
    let mut out = Vec::new();
    for (i, sc) in screens.iter_mut().enumerate() {
        let mut entry = RankEntry {
            effect: sc.effect.name.into(),
            score: sc.stat,
            dof: sc.dof,
            p_value: sc.p_value,
            fitted: false,
            delta_bic: None,
            holdout_error: None,
            closure_fraction: None,
            ci_low: None,
            ci_high: None,
            params: Vec::new(),
            note: sc.note.clone(),
        };
        if fit_set.contains(&i) {
            match fit_effect(prof, sc, opts.newton_iters, n_free) {
                Ok(est) => {
                    let best = sc.best_fit.as_ref().expect("set by fit_effect");
                    entry.fitted = true;
                    entry.params = est;
                    entry.holdout_error = Some(best.holdout_error);
                    entry.delta_bic = Some(
                        n_h * (best.holdout_error / nominal.holdout_error).ln()
                            + sc.dof as f64 * n_h.ln(),
                    );
                    if !sc.stat.is_finite() {
                        // the profile is not convex at the null (fit noise at the design step):
                        // the likelihood-ratio statistic of the fit, asymptotically equivalent
                        let lr = ((nominal.s_train - best.s_train) / sc.s2).max(0.0);
                        entry.score = lr;
                        entry.p_value = chi2_sf(lr, sc.dof);
                        entry.note = Some("score: profiled cost not convex at the null; likelihood-ratio statistic used".into());
                    }
                }
                Err(e) => entry.note = Some(e),
            }
        }
        out.push(entry);
    }
    out.sort_by(|a, b| match (a.delta_bic, b.delta_bic) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.p_value.total_cmp(&b.p_value),
    });
    (out, screens)
}
