//! **Which**: the score (Lagrange-multiplier) test of each omitted effect at its null value.
//!
//! For an effect with strength parameters `theta` (null 0) the log-likelihood of the driven
//! subsystems is `l = -S / (2 s^2)`, with `S` the noise-normalized sum of squared residuals
//! and `s^2 = S_0 / (N - p)` the residual variance factor of the calibrated nominal model.
//! The statistic is `g' I^-1 g` with `g = dl/dtheta` and the Gauss-Newton information
//! `I = J'J / s^2`, both with the nominal parameters profiled out: `S` is evaluated by
//! re-fitting the nominal parameters at a few small settings of `theta` around the null
//! (`0, h, 2h` per parameter, plus `(h, h)` for two-parameter effects), and its gradient and
//! curvature at the null come from the exact quadratic through those points. By the envelope
//! theorem this gradient is the partial gradient at the constrained optimum and the curvature
//! is the Schur complement of the information, so the statistic equals `g_e' [I^-1]_ee g_e`.
//! It is chi-square with `dof = len(theta)` under the null. The profile route (rather than
//! the stage Jacobians directly) also covers the sensor effects, which are not model
//! parameters. Effects whose strength cannot be negative are tested one-sided (a gradient
//! pointing to negative strength gives 0).

use nalgebra::{DMatrix, DVector};

use super::{chi2_sf, Eval, Profile};
use crate::effects::{EffectInfo, EffectTarget};

/// Design step of the screen, as a fraction of each parameter's typical value: small, so
/// that the quadratic model at the null is local (the profile is far from quadratic over
/// strengths that change the engine's behaviour).
pub const SCREEN_STEP: f64 = 0.05;

/// A quadratic model `S(center + d) = c + g'd + d'Hd/2`.
#[derive(Clone, Debug)]
pub struct Quad {
    pub center: Vec<f64>,
    pub c: f64,
    pub g: Vec<f64>,
    pub h: Vec<Vec<f64>>,
}

impl Quad {
    /// Least-squares quadratic through evaluated points (needs at least 1 + k + k(k+1)/2).
    pub fn fit(points: &[&Eval], center: &[f64], scale: &[f64]) -> Option<Quad> {
        let k = center.len();
        let nc = 1 + k + k * (k + 1) / 2;
        if points.len() < nc {
            return None;
        }
        let row = |th: &[f64]| -> Vec<f64> {
            let d: Vec<f64> = (0..k).map(|i| (th[i] - center[i]) / scale[i]).collect();
            let mut r = vec![1.0];
            r.extend(d.iter().copied());
            for a in 0..k {
                for b in a..k {
                    r.push(if a == b {
                        0.5 * d[a] * d[a]
                    } else {
                        d[a] * d[b]
                    });
                }
            }
            r
        };
        let a = DMatrix::from_fn(points.len(), nc, |i, j| row(&points[i].theta)[j]);
        let y = DVector::from_fn(points.len(), |i, _| points[i].s_train);
        let sol = a.clone().svd(true, true).solve(&y, 1e-12).ok()?;
        let mut h = vec![vec![0.0; k]; k];
        let mut m = 1 + k;
        for a in 0..k {
            for b in a..k {
                h[a][b] = sol[m] / (scale[a] * scale[b]);
                h[b][a] = h[a][b];
                m += 1;
            }
        }
        Some(Quad {
            center: center.to_vec(),
            c: sol[0],
            g: (0..k).map(|i| sol[1 + i] / scale[i]).collect(),
            h,
        })
    }

    /// `H^-1 g` (None unless H is positive definite).
    pub fn newton(&self) -> Option<Vec<f64>> {
        let k = self.g.len();
        let h = DMatrix::from_fn(k, k, |a, b| self.h[a][b]);
        let ch = h.cholesky()?;
        let s = ch.solve(&DVector::from_column_slice(&self.g));
        Some(s.iter().copied().collect())
    }

    /// `g' H^-1 g` on the admissible subset (bounded parameters whose Newton step would go
    /// negative from the null are dropped).
    pub fn quad_form(&self, bounded: &[bool], at_null: bool) -> f64 {
        let k = self.g.len();
        let mut keep: Vec<usize> = (0..k).collect();
        for _ in 0..k {
            let h = DMatrix::from_fn(keep.len(), keep.len(), |a, b| self.h[keep[a]][keep[b]]);
            let g = DVector::from_fn(keep.len(), |a, _| self.g[keep[a]]);
            let Some(ch) = h.cholesky() else {
                return f64::NAN;
            };
            let step = ch.solve(&g);
            // the minimizer moves by -step: a bounded parameter at its null must move up
            let bad: Vec<usize> = (0..keep.len())
                .filter(|&a| at_null && bounded[keep[a]] && -step[a] < 0.0)
                .collect();
            if bad.is_empty() {
                return g.dot(&step);
            }
            keep = keep
                .iter()
                .enumerate()
                .filter(|(a, _)| !bad.contains(a))
                .map(|(_, &i)| i)
                .collect();
            if keep.is_empty() {
                return 0.0;
            }
        }
        0.0
    }
}

/// The screen of one effect.
#[derive(Clone, Debug)]
pub struct Screen {
    pub effect: &'static EffectInfo,
    pub stat: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Evaluated settings (the null first).
    pub points: Vec<Eval>,
    /// Design step per strength parameter.
    pub step: Vec<f64>,
    pub bounded: Vec<bool>,
    /// Residual variance factor of the nominal model.
    pub s2: f64,
    /// Set by the ranking: the best fit of this effect.
    pub best_fit: Option<Eval>,
    pub note: Option<String>,
}

/// Whether a strength parameter must stay on the positive side of its null.
pub fn bounded(e: &EffectInfo, name: &str) -> bool {
    !(e.target == EffectTarget::Sensor && name.starts_with("gain"))
}

/// Screen an effect: the score statistic at the null.
pub fn screen(prof: &Profile, e: &'static EffectInfo, nominal: &Eval, n_free: usize) -> Screen {
    let qs = Profile::strengths(e);
    let k = qs.len();
    let step: Vec<f64> = qs.iter().map(|q| SCREEN_STEP * q.typical).collect();
    let bnd: Vec<bool> = qs.iter().map(|q| bounded(e, q.name)).collect();
    let s2 = nominal.s_train / (nominal.n_train.saturating_sub(n_free)).max(1) as f64;
    let mut null = nominal.clone();
    null.theta = vec![0.0; k];
    let mut sc = Screen {
        effect: e,
        stat: f64::NAN,
        dof: k,
        p_value: f64::NAN,
        points: vec![null],
        step: step.clone(),
        bounded: bnd.clone(),
        s2,
        best_fit: None,
        note: None,
    };
    let mut design: Vec<Vec<f64>> = Vec::new();
    for i in 0..k {
        for m in [1.0, 2.0] {
            let mut th = vec![0.0; k];
            th[i] = m * step[i];
            design.push(th);
        }
    }
    if k == 2 {
        design.push(step.clone());
    }
    for th in design {
        match prof.eval(Some(e), &th, &nominal.p) {
            Ok(ev) => sc.points.push(ev),
            Err(err) => {
                sc.note = Some(format!("screen at {th:?} failed: {err}"));
                return sc;
            }
        }
    }
    if std::env::var_os("STIRLING_DIAGNOSE_DEBUG").is_some() {
        for p in &sc.points {
            eprintln!(
                "screen {} theta {:?}: S {:.3} (n {}), holdout {:.4}",
                e.name, p.theta, p.s_train, p.n_train, p.holdout_error
            );
        }
    }
    let pts: Vec<&Eval> = sc.points.iter().collect();
    let Some(q) = Quad::fit(&pts, &vec![0.0; k], &step) else {
        sc.note = Some("too few points for the quadratic model".into());
        return sc;
    };
    let form = q.quad_form(&bnd, true);
    // l = -S/(2 s2): g' I^-1 g = (dS' H_S^-1 dS) / (2 s2)
    sc.stat = if form.is_finite() {
        (form / (2.0 * s2)).max(0.0)
    } else {
        f64::NAN
    };
    if !sc.stat.is_finite() {
        sc.note = Some("the profiled cost is not convex at the null".into());
        sc.stat = f64::NAN;
        return sc;
    }
    sc.p_value = chi2_sf(sc.stat, k);
    sc
}
