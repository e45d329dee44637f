//! The sim-to-real gap diagnosis (method and results: docs/diagnosis.md):
//! calibrate the nominal model on a training block with the two driven subsystems
//! ([`crate::fit`]), then
//! - **where** ([`localize`]): residuals per channel, per harmonic of the cycle, per phase of
//!   the cycle, per subsystem (stage-1 mechanics vs stage-2 gas), and limit-cycle features of
//!   the measured record against a free run of the calibrated model;
//! - **which** ([`score`]): a robust score (Lagrange-multiplier) test of every candidate effect
//!   at its null, from one Jacobian of the joint problem ([`joint`]: the calibrated stages the
//!   effect touches, extended by its variables);
//! - fit every candidate jointly with the nominal variables of those stages and rank them by
//!   held-out error with a BIC penalty ([`rank`]);
//! - **how far** ([`closure`]): the fraction of the held-out excess error closed by the winner,
//!   with a bootstrap interval over whole cycles; the [`verdict`].

pub mod closure;
pub mod joint;
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
use crate::effects::{self, EffectInfo};

use crate::fit::{self, FitOptions, FittedStage};
use crate::signal::{high_pass, noise_sigma, project_drift};
use joint::Joint;

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
    /// Levenberg-Marquardt iterations of each candidate's joint fit.
    pub joint_iters: usize,
    /// Bootstrap resamples for the closure interval.
    pub bootstrap: usize,
    /// Monte Carlo draws of the input noise for the score's variance (0: output noise only).
    pub noise_draws: usize,
    /// Family-wise significance level of the score screen (Bonferroni over the candidates).
    pub alpha: f64,
    pub seed: u64,
    /// Log-normal prior on the nominal parameters around their starting values (log standard
    /// deviation; `None`: none). An omitted effect can often be mimicked by moving nominal
    /// parameters far from their estimates (a leak by the heat-transfer coefficients); the
    /// prior makes such a move cost, so the effect shows in the score.
    pub prior: Option<f64>,
}

/// The default prior spread of the nominal parameters: log standard deviation 0.5 (a factor
/// 1.65 at one standard deviation), wide against the accuracy of spring rates and masses,
/// about the accuracy of heat-transfer and damping estimates.
pub const DEFAULT_PRIOR: f64 = 0.5;

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            effects: None,
            train: None,
            holdout: None,
            fit: FitOptions::default(),
            joint_iters: 12,
            noise_draws: 40,
            bootstrap: 400,
            alpha: 0.01,
            seed: 7,
            prior: Some(DEFAULT_PRIOR),
        }
    }
}

/// One channel's error on the held-out block.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelError {
    pub channel: String,
    /// RMS of measured minus model (channel units), slow part removed as in every error.
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
    /// How far the calibration moved each fitted parameter from its starting value: a gap
    /// can hide in the parameters (a leak absorbed by the heat-transfer coefficients).
    pub shifts: Vec<ParamShift>,
}

/// One calibrated parameter against its starting value.
#[derive(Clone, Debug, Serialize)]
pub struct ParamShift {
    pub name: String,
    pub start: f64,
    pub calibrated: f64,
    /// `calibrated / start`.
    pub factor: f64,
    /// `ln(factor)` in prior standard deviations (`None` without a prior).
    pub prior_sd: Option<f64>,
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
    /// BIC change on the held-out block plus the change of the nominal parameters' prior
    /// cost (negative: better than the nominal model; see [`rank`]).
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
    /// Fits run (the nominal calibration and every joint fit).
    pub fits: usize,
    pub seconds: f64,
    /// Residual series (nominal and winner) on the record, for the report.
    #[serde(skip)]
    pub before: Option<Eval>,
    #[serde(skip)]
    pub after: Option<Eval>,
}

/// The residuals of one model (nominal or with an effect) on the record.
#[derive(Clone, Debug)]
pub struct Eval {
    /// Effect values (empty for the nominal model).
    pub theta: Vec<f64>,
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
    /// All model parameters (effect values applied).
    pub p: Vec<f64>,
}

/// A model prediction of one channel in measured space, from sample `first` on.
#[derive(Clone, Debug)]
pub struct Prediction {
    pub channel: String,
    pub first: usize,
    pub values: Vec<f64>,
    /// Drift cosines per sample that the stage's fit ignores ([`crate::fit::driven::Stage::drift`]):
    /// the same band is projected out of this channel's residuals on every block.
    pub drift_rate: f64,
}

/// The prediction of a fitted stage at variables `u`, from its training start to `last`.
pub fn predict(st: &FittedStage, u: &[f64], last: usize) -> Result<Vec<Prediction>, String> {
    let run = st
        .stage
        .run(u, st.first, last, false)
        .map_err(|e| e.to_string())?;
    Ok(st
        .stage
        .outputs
        .iter()
        .zip(run.yhat)
        .map(|(o, values)| Prediction {
            channel: o.channel.clone(),
            first: run.first,
            values,
            drift_rate: st.stage.drift as f64 / st.keep.len().max(1) as f64,
        })
        .collect())
}

/// What every evaluation of a diagnosis shares.
pub struct Context<'a> {
    pub model: &'a dyn Model,
    pub data: &'a Measured,
    /// Per-channel noise from the original record.
    pub noise: Vec<(String, f64)>,
    /// Training sample range (after the burn-in) and held-out range, inclusive-exclusive.
    pub train_idx: (usize, usize),
    pub hold_idx: (usize, usize),
    /// Half-width (samples) of the moving average removed from the residuals (half a cycle).
    pub half_period: usize,
    /// Bartlett bandwidth of the robust score test (samples).
    pub lag: usize,
    /// The calibrated nominal parameters.
    pub p_nom: Vec<f64>,
    /// The nominal stages' predictions (per stage), reused for stages an effect leaves alone.
    pub nominal_preds: Vec<Vec<Prediction>>,
    /// Per nominal stage: Monte Carlo draws of how input noise moves its weighted residuals.
    pub input_noise: Vec<Vec<Vec<f64>>>,
    /// Joint fits run.
    pub fits: std::sync::atomic::AtomicUsize,
}

impl Context<'_> {
    /// The noise level of a channel (1 if unknown).
    pub fn noise_of(&self, ch: &str) -> f64 {
        self.noise
            .iter()
            .find(|(c, _)| c == ch)
            .map(|(_, s)| *s)
            .unwrap_or(1.0)
    }

    /// The recorded excursion of a position channel about its mean (99.5th percentile).
    pub fn excursion(&self, ch: &str) -> Option<f64> {
        let v = self.data.channel(ch)?;
        let m = cycle_mean(v);
        let mut a: Vec<f64> = v.iter().map(|s| (s - m).abs()).collect();
        a.sort_by(f64::total_cmp);
        a.get((a.len() as f64 * 0.995) as usize).copied()
    }

    /// Residual samples (all channels) on the held-out block.
    pub fn holdout_points(&self, ev: &Eval) -> usize {
        (self.hold_idx.1 - self.hold_idx.0) * ev.channels.len()
    }

    /// The evaluation of a set of predictions (effect values `theta`, parameters `p`).
    pub fn eval(&self, preds: &[Prediction], theta: Vec<f64>, p: Vec<f64>) -> Result<Eval, String> {
        let nt = self.data.t.len();
        let (mut channels, mut resid, mut pred) = (Vec::new(), Vec::new(), Vec::new());
        for pr in preds {
            let meas = self
                .data
                .channel(&pr.channel)
                .ok_or_else(|| format!("channel `{}` missing", pr.channel))?;
            let mut r = vec![f64::NAN; nt];
            let mut pv = vec![f64::NAN; nt];
            for (k, v) in pr.values.iter().enumerate() {
                let i = pr.first + k;
                if i < nt {
                    r[i] = meas[i] - v;
                    pv[i] = *v;
                }
            }
            channels.push(pr.channel.clone());
            resid.push(r);
            pred.push(pv);
        }
        if channels.is_empty() {
            return Err("the calibration produced no output series".into());
        }
        let hp: Vec<Vec<f64>> = resid
            .iter()
            .zip(preds)
            .map(|(r, pr)| {
                let mut h = high_pass(r, self.half_period);
                for (a, b) in [self.train_idx, self.hold_idx] {
                    let m = (pr.drift_rate * (b - a) as f64).round() as usize;
                    if m > 0 && h[a..b].iter().all(|v| v.is_finite()) {
                        project_drift(&mut h[a..b], m);
                    }
                }
                h
            })
            .collect();
        let sample_err = |range: (usize, usize)| -> Result<f64, String> {
            let mut total = 0.0;
            for i in range.0..range.1 {
                for (c, r) in channels.iter().zip(&hp) {
                    let z = r[i] / self.noise_of(c);
                    if !z.is_finite() {
                        return Err(format!("no model output for `{c}` at sample {i}"));
                    }
                    total += z * z;
                }
            }
            let n = ((range.1 - range.0) * channels.len()).max(1) as f64;
            Ok(total / n)
        };
        let train_error = sample_err(self.train_idx)?;
        let holdout_error = sample_err(self.hold_idx)?;
        Ok(Eval {
            theta,
            holdout_error,
            train_error,
            channels,
            resid,
            hp,
            pred,
            p,
        })
    }

    /// The evaluation of a fitted joint problem: its stages at `u`, the others nominal.
    pub fn eval_joint(&self, joint: &Joint, u: &[f64], theta: Vec<f64>) -> Result<Eval, String> {
        let last = self.hold_idx.1 - 1;
        let mut preds = Vec::new();
        for (si, nom) in self.nominal_preds.iter().enumerate() {
            match joint.stages.iter().position(|(s, _)| *s == si) {
                Some(k) => preds.extend(predict(&joint.stages[k].1, &joint.stage_u(k, u), last)?),
                None => preds.extend(nom.iter().cloned()),
            }
        }
        let mut p = self.p_nom.clone();
        for (v, val) in joint.effect.iter().zip(&theta) {
            if let Some(i) = self.model.param_index(&v.name) {
                p[i] = *val;
            }
        }
        self.eval(&preds, theta, p)
    }
}

/// The candidate effects of a diagnosis.
fn candidates(
    model: &dyn Model,
    names: &Option<Vec<String>>,
) -> Result<Vec<&'static EffectInfo>, DiagnoseError> {
    let base = model.name().trim_end_matches("_fx").to_string();
    let Some(names) = names else {
        return Ok(effects::effects_for(&base));
    };
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
    Ok(v)
}

/// Training and held-out blocks (times and sample ranges) of a record.
struct Blocks {
    train: (f64, f64),
    holdout: (f64, f64),
    train_idx: (usize, usize),
    hold_idx: (usize, usize),
}

fn blocks(data: &Measured, opts: &DiagnoseOptions) -> Result<Blocks, DiagnoseError> {
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
            "the training and held-out blocks need at least 50 samples each (after the burn-in)"
                .into(),
        ));
    }
    Ok(Blocks {
        train,
        holdout,
        train_idx,
        hold_idx,
    })
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
    let b = blocks(data, opts)?;
    let cands = candidates(model, &opts.effects)?;
    let noise: Vec<(String, f64)> = data
        .channels()
        .iter()
        .filter_map(|c| {
            data.channel(c)
                .map(|v| (c.to_string(), noise_sigma(v).max(1e-12)))
        })
        .collect();
    let mut fit_opts = opts.fit.clone();
    fit_opts.train = Some(b.train);
    fit_opts.holdout = Some(b.holdout);
    // the diagnosis needs the stages, not the validation extras
    fit_opts.free_run = None;
    fit_opts.multiple_shooting = None;
    fit_opts.input_noise_draws = 0;
    fit_opts.prior = opts.prior;
    let (id, stages) = fit::identify_stages(model, p0, data, &fit_opts)
        .map_err(|e| DiagnoseError::Nominal(e.to_string()))?;
    let mut p_nom = p0.to_vec();
    for (name, v) in &id.params {
        if let Some(i) = model.param_index(name) {
            p_nom[i] = *v;
        }
    }
    let starts = crate::signal::cycle_starts(data, (b.train_idx.0, b.hold_idx.1));
    let period = if starts.len() >= 2 {
        (starts[starts.len() - 1] - starts[0]) / (starts.len() - 1)
    } else {
        0
    };
    let last = b.hold_idx.1 - 1;
    let nominal_preds = stages
        .iter()
        .map(|st| predict(st, &st.u, last))
        .collect::<Result<Vec<_>, String>>()
        .map_err(DiagnoseError::Nominal)?;
    let ctx = Context {
        model,
        data,
        noise,
        train_idx: b.train_idx,
        hold_idx: b.hold_idx,
        half_period: period / 2,
        lag: score::bandwidth(b.train_idx.1 - b.train_idx.0, period),
        p_nom: p_nom.clone(),
        nominal_preds,
        input_noise: stages
            .iter()
            .map(|st| {
                st.stage.input_noise_draws(
                    &st.u,
                    st.first,
                    st.last,
                    &st.keep,
                    opts.noise_draws,
                    opts.seed,
                )
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| DiagnoseError::Nominal(e.to_string()))?,
        fits: std::sync::atomic::AtomicUsize::new(1),
    };
    let all: Vec<Prediction> = ctx.nominal_preds.iter().flatten().cloned().collect();
    let nominal = ctx
        .eval(&all, vec![], p_nom.clone())
        .map_err(DiagnoseError::Nominal)?;
    let s2 = stages
        .iter()
        .map(joint::variance_factor)
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|e| DiagnoseError::Nominal(e.to_string()))?;
    let localization = localize::localize(model, &p_nom, data, &nominal, &ctx);
    if std::env::var_os("STIRLING_DIAGNOSE_DEBUG").is_some() {
        eprintln!("nominal parameters: {:?}", id.params);
        for c in &localization.channels {
            eprintln!(
                "nominal {}: train {:.3}, held-out {:.3} x noise; s2 {s2:?}",
                c.channel, c.train_ratio, c.holdout_ratio
            );
        }
    }
    let mut lm = opts.fit.lm;
    lm.max_iter = opts.joint_iters;
    // trial steps of at most one typical strength: far trials (an engine stopped by friction)
    // are slow to integrate and rejected anyway
    lm.max_step = 1.0;
    // the candidates are independent: one per core
    let mut assessed: Vec<rank::Assessed> = {
        use rayon::prelude::*;
        cands
            .par_iter()
            .map(|e| rank::assess(&ctx, &stages, &s2, &nominal, e, &lm))
            .collect()
    };
    rank::sort(&mut assessed, opts.alpha / cands.len().max(1) as f64);
    for a in assessed.iter_mut() {
        if let Some(ev) = &a.eval {
            let c = closure::closure(
                data,
                &nominal,
                ev,
                ctx.hold_idx,
                &ctx,
                opts.bootstrap,
                opts.seed,
            );
            a.entry.closure_fraction = Some(c.fraction);
            a.entry.ci_low = Some(c.ci_low);
            a.entry.ci_high = Some(c.ci_high);
        }
    }
    let after = assessed.first().and_then(|a| a.eval.clone());
    let ranking: Vec<RankEntry> = assessed.into_iter().map(|a| a.entry).collect();
    let gap_before = gap_before(&ctx, &nominal, &stages, &localization);
    let verdict = verdict::decide(
        &ranking,
        &nominal,
        opts.alpha,
        cands.len(),
        &gap_before.shifts,
    );
    Ok(Diagnosis {
        model: model.name().into(),
        n: model.n(),
        train: b.train,
        holdout: b.holdout,
        gap_before,
        localization,
        ranking,
        verdict,
        fits: ctx.fits.load(std::sync::atomic::Ordering::Relaxed),
        seconds: clock.elapsed().as_secs_f64(),
        before: Some(nominal),
        after,
    })
}

/// The nominal model's held-out gap per channel, with features and calibrated parameters.
fn gap_before(
    ctx: &Context,
    nominal: &Eval,
    stages: &[FittedStage],
    loc: &localize::Localization,
) -> GapBefore {
    let (a, b) = ctx.hold_idx;
    let channels = nominal
        .channels
        .iter()
        .zip(&nominal.hp)
        .map(|(c, r)| {
            let rms = (r[a..b].iter().map(|v| v * v).sum::<f64>() / (b - a) as f64).sqrt();
            let s = ctx.noise_of(c);
            ChannelError {
                channel: c.clone(),
                rms,
                noise: s,
                ratio: rms / s,
            }
        })
        .collect();
    let fitted: Vec<(&fit::driven::Var, f64)> = stages
        .iter()
        .flat_map(|st| st.stage.vars.iter())
        .filter_map(|v| match v.kind {
            fit::driven::VarKind::Param(i) => Some((v, ctx.p_nom[i])),
            _ => None,
        })
        .collect();
    let params = fitted.iter().map(|(v, x)| (v.name.clone(), *x)).collect();
    let shifts = fitted
        .iter()
        .filter(|(v, _)| v.initial != 0.0)
        .map(|(v, x)| {
            let factor = x / v.initial;
            ParamShift {
                name: v.name.clone(),
                start: v.initial,
                calibrated: *x,
                factor,
                prior_sd: v.prior.filter(|_| factor > 0.0).map(|s| factor.ln() / s),
            }
        })
        .collect();
    GapBefore {
        shifts,
        channels,
        holdout_error: nominal.holdout_error,
        train_error: nominal.train_error,
        features: loc.features.clone(),
        params,
    }
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
