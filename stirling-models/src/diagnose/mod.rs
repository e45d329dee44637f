//! The sim-to-real gap diagnosis (DESIGN.md, "The gap diagnosis, in outline"):
//! calibrate the nominal model on a training block with the two driven subsystems
//! ([`crate::fit`]), then
//! - **where** ([`localize`]): residuals per channel, per harmonic of the cycle, per phase of
//!   the cycle, per subsystem (stage-1 mechanics vs stage-2 gas), and limit-cycle features of
//!   the measured record against a free run of the calibrated model;
//! - **which** ([`score`]): a score (Lagrange-multiplier) test of every candidate effect at
//!   its null value, on the profiled cost of the driven subsystems;
//! - fit the promising candidates jointly with the nominal parameters and rank them by
//!   held-out error with a BIC penalty ([`rank`]);
//! - **how far** ([`closure`]): the fraction of the held-out excess error closed by the winner,
//!   with a bootstrap interval over whole cycles; the [`verdict`].
//!
//! The profile machinery ([`Profile`]): for an effect with strength parameters `theta`, the
//! nominal free parameters are re-fitted by the two-stage identification with `theta` fixed,
//! and the residuals are taken in the *measured* space (sensor effects act on the model
//! outputs: a gain multiplies them, a lag filters them), normalized by each channel's noise
//! level estimated from the data. The cost `S(theta)` is thus minimized over the nominal
//! parameters; its gradient at the null is the score of `theta` with the nuisance parameters
//! profiled out (envelope theorem), and its curvature is the Schur complement of the
//! Gauss-Newton information, i.e. `[I^-1]_theta,theta ^-1`.

pub mod closure;
pub mod localize;
pub mod rank;
pub mod report;
pub mod score;
pub mod selfcheck;
pub mod verdict;

use std::time::Instant;

use serde::Serialize;
use stirling_dsl::{Closure, Model};

use crate::data::{cycle_mean, Measured};
use crate::effects::{self, EffectInfo, EffectTarget};
use crate::fit::driven::{noise_sigma, savitzky_golay};
use crate::fit::{self, FitOptions, Identification};

/// Why a diagnosis failed.
#[derive(Clone, Debug, thiserror::Error)]
pub enum DiagnoseError {
    #[error("{0}")]
    Bad(String),
    #[error("the nominal calibration failed: {0}")]
    Nominal(String),
}

/// Options of a diagnosis.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// Candidate effects (`None`: every effect that applies to the model).
    pub effects: Option<Vec<String>>,
    /// Training block (default: the first 60 % of the record).
    pub train: Option<(f64, f64)>,
    /// Held-out block (default: the rest).
    pub holdout: Option<(f64, f64)>,
    /// Options of the underlying two-stage fits.
    pub fit: FitOptions,
    /// How many of the best-scoring candidates are fitted and ranked (at least the significant ones;
    /// default: all, since the profile screen is noisy where the two-stage refit is not idempotent).
    pub max_fit: usize,
    /// Newton iterations on the profiled cost when fitting a candidate.
    pub newton_iters: usize,
    /// Bootstrap resamples for the closure interval.
    pub bootstrap: usize,
    /// Family-wise significance level of the score screen (Bonferroni over the candidates).
    pub alpha: f64,
    pub seed: u64,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            effects: None,
            train: None,
            holdout: None,
            fit: FitOptions::default(),
            max_fit: 8,
            newton_iters: 4,
            bootstrap: 400,
            alpha: 0.01,
            seed: 7,
        }
    }
}

/// One channel's error on the held-out block.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelError {
    pub channel: String,
    /// RMS of measured minus model (channel units).
    pub rms: f64,
    /// Noise level estimated from the data (third differences).
    pub noise: f64,
    /// `rms / noise`: 1 is the noise floor.
    pub ratio: f64,
}

/// The gap of the calibrated nominal model.
#[derive(Clone, Debug, Serialize)]
pub struct GapBefore {
    /// Held-out error per channel.
    pub channels: Vec<ChannelError>,
    /// Held-out mean squared error in units of the noise variance (1: the noise floor).
    pub holdout_error: f64,
    /// The same on the training block.
    pub train_error: f64,
    /// Limit-cycle features, measured vs free run of the calibrated model.
    pub features: localize::Features,
    /// The calibrated nominal parameters (the fitted subset).
    pub params: Vec<(String, f64)>,
}

/// One candidate effect in the ranking.
#[derive(Clone, Debug, Serialize)]
pub struct RankEntry {
    pub effect: String,
    /// Score statistic `g' I^-1 g` at the null.
    pub score: f64,
    pub dof: usize,
    pub p_value: f64,
    /// Fitted jointly with the nominal parameters (the promising ones only).
    pub fitted: bool,
    /// BIC change on the held-out block (negative: better than the nominal model).
    pub delta_bic: Option<f64>,
    pub holdout_error: Option<f64>,
    pub closure_fraction: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// Fitted effect parameters with 95 % intervals.
    pub params: Vec<EffectEstimate>,
    /// Why it could not be screened or fitted, if so.
    pub note: Option<String>,
}

/// A fitted effect parameter.
#[derive(Clone, Debug, Serialize)]
pub struct EffectEstimate {
    pub name: String,
    pub value: f64,
    pub std_error: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub unit: String,
}

/// The diagnosis.
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    pub model: String,
    pub n: usize,
    pub train: (f64, f64),
    pub holdout: (f64, f64),
    pub gap_before: GapBefore,
    pub localization: localize::Localization,
    pub ranking: Vec<RankEntry>,
    pub verdict: verdict::Verdict,
    /// Number of two-stage fits run.
    pub fits: usize,
    pub seconds: f64,
    /// Residual series (nominal and winner) on the record, for the report.
    #[serde(skip)]
    pub before: Option<Eval>,
    #[serde(skip)]
    pub after: Option<Eval>,
}

/// One evaluation of the profiled cost at an effect setting.
#[derive(Clone, Debug)]
pub struct Eval {
    pub theta: Vec<f64>,
    /// Training cost: sum over channels and samples of (residual / noise)^2.
    pub s_train: f64,
    pub n_train: usize,
    /// Held-out mean of the per-sample, channel-averaged (residual / noise)^2.
    pub holdout_error: f64,
    pub train_error: f64,
    /// Channel names and, per channel, the residual (measured minus model) on the whole
    /// evaluated range (`NaN` outside it) and the model prediction in measured space.
    pub channels: Vec<String>,
    pub resid: Vec<Vec<f64>>,
    /// The residuals with their slow part (a centered moving average over one cycle) removed:
    /// what the costs and errors use.
    pub hp: Vec<Vec<f64>>,
    pub pred: Vec<Vec<f64>>,
    /// All model parameters after the re-fit.
    pub p: Vec<f64>,
}

/// The profiled cost of a model on a record.
pub struct Profile<'a> {
    pub model: &'a dyn Model,
    pub data: &'a Measured,
    /// Per-channel noise from the original record.
    pub noise: Vec<(String, f64)>,
    pub fit: FitOptions,
    /// Training sample range (after the burn-in) and held-out range, inclusive-exclusive.
    pub train_idx: (usize, usize),
    pub hold_idx: (usize, usize),
    /// Count of two-stage fits run.
    pub count: std::cell::Cell<usize>,
    /// Half-width (samples) of the moving average removed from the residuals (half a cycle).
    pub half_period: usize,
}

/// Remove the centered moving average of half-width `h` (over the finite samples), scaled so
/// that white noise keeps its variance.
pub fn high_pass(r: &[f64], h: usize) -> Vec<f64> {
    let n = r.len();
    let mut cs = vec![0.0; n + 1];
    let mut cn = vec![0usize; n + 1];
    for i in 0..n {
        let ok = r[i].is_finite();
        cs[i + 1] = cs[i] + if ok { r[i] } else { 0.0 };
        cn[i + 1] = cn[i] + ok as usize;
    }
    let w = (2 * h + 1) as f64;
    let gain = 1.0 / (1.0 - 1.0 / w).sqrt();
    (0..n)
        .map(|i| {
            if !r[i].is_finite() || h == 0 {
                return r[i];
            }
            let (a, b) = (i.saturating_sub(h), (i + h + 1).min(n));
            let m = (cs[b] - cs[a]) / (cn[b] - cn[a]).max(1) as f64;
            gain * (r[i] - m)
        })
        .collect()
}

impl Profile<'_> {
    /// Strength parameters of an effect (those with a null value).
    pub fn strengths(e: &EffectInfo) -> Vec<&'static effects::EffectParam> {
        e.params.iter().filter(|q| q.null.is_some()).collect()
    }

    fn noise_of(&self, ch: &str) -> f64 {
        self.noise
            .iter()
            .find(|(c, _)| c == ch)
            .map(|(_, s)| *s)
            .unwrap_or(1.0)
    }

    /// Re-fit the nominal parameters from `start` with the effect `e` at `theta`, and return
    /// the residuals in measured space.
    pub fn eval(
        &self,
        e: Option<&EffectInfo>,
        theta: &[f64],
        start: &[f64],
    ) -> Result<Eval, String> {
        self.count.set(self.count.get() + 1);
        let mut p = start.to_vec();
        let mut data = self.data.clone();
        let (mut gain_x, mut gain_y, mut tau) = (0.0, 0.0, 0.0);
        if let Some(e) = e {
            for (q, &v) in Self::strengths(e).iter().zip(theta) {
                match (e.target, q.name) {
                    (EffectTarget::Model, name) => {
                        let i = self.model.param_index(name).ok_or_else(|| {
                            format!("model `{}` has no parameter `{name}`", self.model.name())
                        })?;
                        p[i] = v;
                    }
                    (EffectTarget::Sensor, "gain_x") => gain_x = v,
                    (EffectTarget::Sensor, "gain_y") => gain_y = v,
                    (EffectTarget::Sensor, "tau_p") => tau = v,
                    (EffectTarget::Sensor, other) => {
                        return Err(format!(
                            "sensor parameter `{other}` is not handled by the diagnosis"
                        ))
                    }
                }
            }
        }
        // sensor effects: undo them on the data for the fit, apply them to the prediction
        if let Some(x) = data.x.as_mut() {
            x.iter_mut().for_each(|v| *v /= 1.0 + gain_x);
        }
        if let Some(y) = data.y.as_mut() {
            y.iter_mut().for_each(|v| *v /= 1.0 + gain_y);
        }
        let dt = data.dt();
        if tau > 0.0 {
            for ch in [data.p.as_mut(), data.p_hot.as_mut()].into_iter().flatten() {
                // invert the lag: u = y + tau y' (the derivative from a local cubic fit)
                let (_, der) = savitzky_golay(ch, dt, 4, 3);
                for (v, d) in ch.iter_mut().zip(&der) {
                    *v += tau * d;
                }
            }
        }
        let id: Identification =
            fit::identify(self.model, &p, &data, &self.fit).map_err(|e| e.to_string())?;
        let mut p_fit = p.clone();
        for (name, v) in &id.params {
            if let Some(i) = self.model.param_index(name) {
                p_fit[i] = *v;
            }
        }
        let nt = self.data.t.len();
        let t0 = self.data.t[0];
        let mut channels = Vec::new();
        let mut resid = Vec::new();
        let mut pred = Vec::new();
        for st in [id.stage1.as_ref(), id.stage2.as_ref()]
            .into_iter()
            .flatten()
        {
            for s in &st.series {
                let meas = self
                    .data
                    .channel(&s.channel)
                    .ok_or_else(|| format!("channel `{}` missing", s.channel))?;
                let model_out: Vec<f64> = match s.channel.as_str() {
                    "x" => s.model.iter().map(|v| v * (1.0 + gain_x)).collect(),
                    "y" => s.model.iter().map(|v| v * (1.0 + gain_y)).collect(),
                    "p" | "p_hot" if tau > 0.0 => crate::rig::first_order_lag(&s.model, dt, tau),
                    _ => s.model.clone(),
                };
                let mut r = vec![f64::NAN; nt];
                let mut pr = vec![f64::NAN; nt];
                for (k, &t) in s.t.iter().enumerate() {
                    let i = ((t - t0) / dt).round() as usize;
                    if i < nt {
                        r[i] = meas[i] - model_out[k];
                        pr[i] = model_out[k];
                    }
                }
                channels.push(s.channel.clone());
                resid.push(r);
                pred.push(pr);
            }
        }
        if channels.is_empty() {
            return Err("the identification produced no output series".into());
        }
        let hp: Vec<Vec<f64>> = resid
            .iter()
            .map(|r| high_pass(r, self.half_period))
            .collect();
        let (mut s_train, mut n_train) = (0.0, 0);
        let sample_err = |range: (usize, usize), acc: Option<&mut f64>| -> Result<f64, String> {
            let (mut sum, mut cnt) = (0.0, 0usize);
            let mut s_acc = 0.0;
            for i in range.0..range.1 {
                let mut e = 0.0;
                for (c, r) in channels.iter().zip(&hp) {
                    let z = r[i] / self.noise_of(c);
                    if !z.is_finite() {
                        return Err(format!("no model output for `{c}` at sample {i}"));
                    }
                    e += z * z;
                }
                s_acc += e;
                sum += e / channels.len() as f64;
                cnt += 1;
            }
            if let Some(a) = acc {
                *a = s_acc;
            }
            Ok(sum / cnt.max(1) as f64)
        };
        let train_error = sample_err(self.train_idx, Some(&mut s_train))?;
        n_train += (self.train_idx.1 - self.train_idx.0) * channels.len();
        let holdout_error = sample_err(self.hold_idx, None)?;
        Ok(Eval {
            theta: theta.to_vec(),
            s_train,
            n_train,
            holdout_error,
            train_error,
            channels,
            resid,
            hp,
            pred,
            p: p_fit,
        })
    }
}

/// Error for parameters that the two-stage fit did not free (used for the BIC count).
fn free_count(model: &dyn Model, p: &[f64], fit: &FitOptions) -> usize {
    fit.free
        .clone()
        .unwrap_or_else(|| fit::default_free(model, p))
        .len()
}

/// Diagnose `model` (a base model with an augmented member: `cv1`, `nsection`) from starting
/// parameters `p0` (of the augmented model, effects at their nulls) on a measured record.
pub fn diagnose(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    if data.t.len() < 100 {
        return Err(DiagnoseError::Bad(format!(
            "{}: {} samples are too few to diagnose",
            data.source,
            data.t.len()
        )));
    }
    let t0 = data.t[0];
    let t1 = data.t[data.t.len() - 1];
    let train = opts.train.unwrap_or((t0, t0 + 0.6 * (t1 - t0)));
    let holdout = opts.holdout.unwrap_or((train.1, t1));
    if holdout.0 < train.1 - 1e-12 {
        return Err(DiagnoseError::Bad(format!(
            "the held-out block {}:{} must start after the training block {}:{}",
            holdout.0, holdout.1, train.0, train.1
        )));
    }
    let dt = data.dt();
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(data.t.len() - 1);
    let burn = (opts.fit.burn_in / dt).round() as usize;
    let train_idx = ((idx(train.0) + burn).min(idx(train.1)), idx(train.1));
    let hold_idx = (idx(holdout.0).max(train_idx.1), idx(holdout.1) + 1);
    if train_idx.1 < train_idx.0 + 50 || hold_idx.1 < hold_idx.0 + 50 {
        return Err(DiagnoseError::Bad(
            "the training and held-out blocks need at least 50 samples each".into(),
        ));
    }
    let noise: Vec<(String, f64)> = data
        .channels()
        .iter()
        .filter_map(|c| {
            data.channel(c)
                .map(|v| (c.to_string(), noise_sigma(v).max(1e-12)))
        })
        .collect();
    let mut fit_opts = opts.fit.clone();
    fit_opts.train = Some(train);
    fit_opts.holdout = Some(holdout);
    // the end stops' travel is a shape parameter: taken from the data (the largest excursion)
    let mut p0 = p0.to_vec();
    for (ch, name) in [("x", "xmax"), ("y", "ymax")] {
        if let (Some(v), Some(i)) = (data.channel(ch), model.param_index(name)) {
            let m = cycle_mean(v);
            let mut a: Vec<f64> = v.iter().map(|s| (s - m).abs()).collect();
            a.sort_by(f64::total_cmp);
            p0[i] = 0.97 * a[(a.len() as f64 * 0.995) as usize];
        }
    }
    let starts = closure::cycle_starts(data, (train_idx.0, hold_idx.1));
    let half_period = if starts.len() >= 2 {
        (starts[starts.len() - 1] - starts[0]) / (starts.len() - 1) / 2
    } else {
        0
    };
    let prof = Profile {
        model,
        data,
        noise: noise.clone(),
        fit: fit_opts.clone(),
        train_idx,
        hold_idx,
        count: std::cell::Cell::new(0),
        half_period,
    };
    let nominal = prof.eval(None, &[], &p0).map_err(DiagnoseError::Nominal)?;
    let p_nom = nominal.p.clone();
    // later fits start at the calibrated point: fewer iterations suffice
    let mut refit = fit_opts.clone();
    refit.lm.max_iter = refit.lm.max_iter.min(30);
    let prof = Profile { fit: refit, ..prof };
    // the reference for every comparison: the nominal model re-fitted from its calibrated point
    // with the same protocol as the candidates (same start, same optimizer settings)
    let nominal = prof
        .eval(None, &[], &p_nom)
        .map_err(DiagnoseError::Nominal)?;
    let p_nom = nominal.p.clone();

    let base = model.name().trim_end_matches("_fx").to_string();
    let candidates: Vec<&'static EffectInfo> = match &opts.effects {
        None => effects::effects_for(&base),
        Some(names) => {
            let mut v = Vec::new();
            for n in names {
                let e = effects::effect(n).ok_or_else(|| {
                    DiagnoseError::Bad(format!(
                        "unknown effect `{n}`: expected one of {}",
                        effects::EFFECTS
                            .iter()
                            .map(|e| e.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })?;
                if !e.applies_to.contains(&base.as_str()) {
                    return Err(DiagnoseError::Bad(format!(
                        "effect `{n}` does not apply to `{base}` (it applies to {})",
                        e.applies_to.join(", ")
                    )));
                }
                v.push(e);
            }
            v
        }
    };
    let n_free = free_count(model, &p_nom, &prof.fit);
    let localization = localize::localize(model, &p_nom, data, &nominal, &prof);
    let screens: Vec<score::Screen> = candidates
        .iter()
        .map(|e| score::screen(&prof, e, &nominal, n_free))
        .collect();
    let (mut ranking, screens) = rank::rank(&prof, &screens, &nominal, n_free, opts);
    let mut after = None;
    if let Some(best) = ranking.first().filter(|r| r.fitted) {
        if let Some(ev) = screens
            .iter()
            .find(|s| s.effect.name == best.effect)
            .and_then(|s| s.best_fit.clone())
        {
            after = Some(ev);
        }
    }
    for r in ranking.iter_mut().filter(|r| r.fitted) {
        if let Some(ev) = screens
            .iter()
            .find(|s| s.effect.name == r.effect)
            .and_then(|s| s.best_fit.as_ref())
        {
            let c = closure::closure(
                data,
                &nominal,
                ev,
                prof.hold_idx,
                &prof,
                opts.bootstrap,
                opts.seed,
            );
            r.closure_fraction = Some(c.fraction);
            r.ci_low = Some(c.ci_low);
            r.ci_high = Some(c.ci_high);
        }
    }
    let verdict = verdict::decide(&ranking, &nominal, opts.alpha, screens.len());
    let channels = nominal
        .channels
        .iter()
        .zip(&nominal.resid)
        .map(|(c, r)| {
            let h: Vec<f64> = r[hold_idx.0..hold_idx.1].to_vec();
            let rms = (h.iter().map(|v| v * v).sum::<f64>() / h.len() as f64).sqrt();
            let s = prof.noise_of(c);
            ChannelError {
                channel: c.clone(),
                rms,
                noise: s,
                ratio: rms / s,
            }
        })
        .collect();
    let free = prof
        .fit
        .free
        .clone()
        .unwrap_or_else(|| fit::default_free(model, &p_nom));
    let params = free
        .iter()
        .filter_map(|n| model.param_index(n).map(|i| (n.clone(), p_nom[i])))
        .collect();
    let features = localization.features.clone();
    Ok(Diagnosis {
        model: model.name().into(),
        n: model.n(),
        train,
        holdout,
        gap_before: GapBefore {
            channels,
            holdout_error: nominal.holdout_error,
            train_error: nominal.train_error,
            features,
            params,
        },
        localization,
        ranking,
        verdict,
        fits: prof.count.get(),
        seconds: clock.elapsed().as_secs_f64(),
        before: Some(nominal),
        after,
    })
}

/// The augmented model of a base model name, with its nominal parameters.
pub fn nominal_model(
    base: &str,
    n: Option<usize>,
) -> Result<(Box<dyn Model>, Vec<f64>), DiagnoseError> {
    let m = effects::augmented(base, n, Closure::Full)
        .map_err(|e| DiagnoseError::Bad(e.to_string()))?;
    let p = effects::nominal_params(m.as_ref());
    Ok((m, p))
}

/// Upper tail of the chi-square distribution with `k` degrees of freedom (k = 1, 2; larger
/// `k` by the Wilson-Hilferty approximation).
pub fn chi2_sf(x: f64, k: usize) -> f64 {
    if !(x > 0.0) {
        return 1.0;
    }
    match k {
        1 => erfc((x / 2.0).sqrt()),
        2 => (-x / 2.0).exp(),
        _ => {
            let k = k as f64;
            let z = ((x / k).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
            0.5 * erfc(z / std::f64::consts::SQRT_2)
        }
    }
}

/// Complementary error function (Numerical Recipes' Chebyshev fit, relative error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let ans = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398
                                    + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        ans
    } else {
        2.0 - ans
    }
}
