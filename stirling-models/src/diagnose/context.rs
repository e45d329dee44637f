//! The evaluation context of one diagnosis: the record, its blocks and noise levels, the
//! nominal predictions, and the residuals of a model (nominal or with an effect) on them.

use stirling_dsl::Model;

use super::joint::Joint;
use super::DiagnoseError;
use crate::data::{cycle_mean, Measured};
use crate::fit::FittedStage;
use crate::signal::{high_pass, project_drift};

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
pub fn predict(st: &FittedStage, u: &[f64], last: usize) -> Result<Vec<Prediction>, DiagnoseError> {
    let run = st.stage.run(u, st.first, last, false)?;
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
    /// Cycle starts (samples) over the training and held-out blocks.
    pub starts: Vec<usize>,
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
    /// Where progress lines go (see [`super::DiagnoseOptions::progress`]).
    pub progress: Option<fn(&str)>,
    /// Stage 1 restarts from the measured body states (the second pass for end stops,
    /// [`super::restarted`]): each body's stops are screened on their own and fitted from
    /// the reset start too.
    pub restarted: bool,
    /// End-stop travels seen in the measured acceleration ([`super::stops_equation`]), in
    /// the model's coordinates: on the restarted pass the stops are screened and fitted at
    /// these travels, held (empty: none seen, or the first pass).
    pub held_travels: Vec<(&'static str, f64)>,
    /// On the one-run pass of a record whose end stops are seen in the measured acceleration:
    /// the channels of the stages that predict no body whose stops are seen (the gas stage,
    /// driven by the measured positions, so blind to the stops), on which every candidate
    /// without travels is also judged ([`super::untouched`]). Empty otherwise.
    pub untouched: Vec<String>,
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
    pub fn eval(
        &self,
        preds: &[Prediction],
        theta: Vec<f64>,
        p: Vec<f64>,
    ) -> Result<Eval, DiagnoseError> {
        if preds.is_empty() {
            return Err(DiagnoseError::NoOutputs);
        }
        let mut series = Vec::new();
        for pr in preds {
            series.push(self.series(pr)?);
        }
        let (resid, pred): (Vec<Vec<f64>>, Vec<Vec<f64>>) = series.into_iter().unzip();
        let channels: Vec<String> = preds.iter().map(|pr| pr.channel.clone()).collect();
        let hp: Vec<Vec<f64>> = resid
            .iter()
            .zip(preds)
            .map(|(r, pr)| self.high_passed(r, pr.drift_rate))
            .collect();
        Ok(Eval {
            theta,
            train_error: self.mean_square(&channels, &hp, self.train_idx)?,
            holdout_error: self.mean_square(&channels, &hp, self.hold_idx)?,
            channels,
            resid,
            hp,
            pred,
            p,
        })
    }

    /// A prediction's residual (measured minus model) and values on the record's grid (`NaN`
    /// where it has none).
    fn series(&self, pr: &Prediction) -> Result<(Vec<f64>, Vec<f64>), DiagnoseError> {
        let meas = self
            .data
            .channel(&pr.channel)
            .ok_or_else(|| DiagnoseError::MissingChannel {
                file: self.data.source.clone(),
                channel: pr.channel.clone(),
            })?;
        let nt = self.data.t.len();
        let mut r = vec![f64::NAN; nt];
        let mut pv = vec![f64::NAN; nt];
        for (k, v) in pr.values.iter().enumerate() {
            let i = pr.first + k;
            if i < nt {
                r[i] = meas[i] - v;
                pv[i] = *v;
            }
        }
        Ok((r, pv))
    }

    /// A residual without its slow part, and, on each block, without the sub-cycle drift
    /// band of `drift_rate` the stage ignores.
    fn high_passed(&self, r: &[f64], drift_rate: f64) -> Vec<f64> {
        let mut h = high_pass(r, self.half_period);
        for (a, b) in [self.train_idx, self.hold_idx] {
            let m = (drift_rate * (b - a) as f64).round() as usize;
            if m > 0 && h[a..b].iter().all(|v| v.is_finite()) {
                project_drift(&mut h[a..b], m);
            }
        }
        h
    }

    /// Mean squared residual over noise variance on the sample `range`, all channels.
    fn mean_square(
        &self,
        channels: &[String],
        hp: &[Vec<f64>],
        range: (usize, usize),
    ) -> Result<f64, DiagnoseError> {
        let mut total = 0.0;
        for i in range.0..range.1 {
            for (c, r) in channels.iter().zip(hp) {
                let z = r[i] / self.noise_of(c);
                if !z.is_finite() {
                    return Err(DiagnoseError::NoModelOutput {
                        channel: c.clone(),
                        sample: i,
                    });
                }
                total += z * z;
            }
        }
        let n = ((range.1 - range.0) * channels.len()).max(1) as f64;
        Ok(total / n)
    }

    /// The evaluation of a fitted joint problem: its stages at `u`, the others nominal.
    pub fn eval_joint(
        &self,
        joint: &Joint,
        u: &[f64],
        theta: Vec<f64>,
    ) -> Result<Eval, DiagnoseError> {
        let last = self.hold_idx.1 - 1;
        let mut preds = Vec::new();
        for (si, nom) in self.nominal_preds.iter().enumerate() {
            match joint.stages.iter().position(|(s, _)| *s == si) {
                Some(k) => preds.extend(predict(&joint.stages[k].1, &joint.stage_u(k, u), last)?),
                None => preds.extend(nom.iter().cloned()),
            }
        }
        let mut p = self.p_nom.clone();
        // the nominal parameters the joint fit moved, then the effect values
        for (k, (_, st)) in joint.stages.iter().enumerate() {
            let vals = st.stage.values(&joint.stage_u(k, u));
            for (v, val) in st.stage.vars.iter().zip(vals) {
                if let crate::fit::vars::VarKind::Param(j) = v.kind {
                    p[j] = val;
                }
            }
        }
        for (v, val) in joint.effect.iter().zip(&theta) {
            if let Some(i) = self.model.param_index(&v.name) {
                p[i] = *val;
            }
        }
        self.eval(&preds, theta, p)
    }
}
