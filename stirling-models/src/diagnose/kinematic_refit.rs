//! The model effects of a kinematic engine, each fitted by the kinematic fit itself: the
//! effect's strengths freed beside the nominal gas parameters, the gas driven by the measured
//! angle, from the estimates (docs/diagnosis.md, "Kinematic engines").
//!
//! Why not the free-piston diagnosis's score and joint fit: on the gamma LTD the leak's
//! first-order signature on the pressure is the film coefficient `hp`'s (they correlate at
//! 0.99: both set the pressure's phase), so at the calibration (where `hp` has absorbed
//! what it can) the score of a withheld leak is not significant (p = 0.05 for 5x the nominal
//! leak) and the joint fit from there stays near the null; fitted together from the
//! estimates, the strength and `hp` separate (the leak at 1.98e-9 for 2e-9). Each candidate is
//! judged on the held-out block: a Wald test of its strength against the null (one-sided,
//! the strength cannot be negative), the held-out BIC change and the closed fraction of the
//! held-out excess error with a bootstrap interval over whole cycles.

use stirling_dsl::Model;

use super::types::{EffectEstimate, Interval, RankEntry};
use super::DiagnoseError;
use crate::data::Measured;
use crate::effects::{EffectInfo, EffectTarget};
use crate::fit::{self, FitOptions, Identification};
use crate::signal::{chi2_sf, cycle_starts, noise_sigma, percentile_interval, resamples};

/// The held-out residuals of one fit, per sample, in noise units squared.
pub(super) struct HeldOut {
    /// Per held-out sample: `(measured - model)^2 / noise^2` (`p` only).
    pub err: Vec<f64>,
    /// The first held-out sample's index in the record.
    pub first: usize,
    pub rms: f64,
}

impl HeldOut {
    pub fn mean(&self) -> f64 {
        self.err.iter().sum::<f64>() / self.err.len().max(1) as f64
    }
}

/// The held-out residuals of the fit `id` on `data` (the block `holdout`, seconds).
pub(super) fn held_out(
    id: &Identification,
    data: &Measured,
    holdout: (f64, f64),
) -> Result<HeldOut, DiagnoseError> {
    let none = || DiagnoseError::NoModelOutput {
        channel: "p".into(),
        sample: 0,
    };
    let series = id
        .stage2
        .as_ref()
        .and_then(|s| s.series.iter().find(|q| q.channel == "p"))
        .ok_or_else(none)?;
    let pm = data.p.as_ref().ok_or_else(none)?;
    let noise = noise_sigma(pm).max(1e-12);
    let dt = data.dt();
    let t0 = data.t[0];
    let mut err = Vec::new();
    let mut first = usize::MAX;
    let mut sq = 0.0;
    for ((&t, &m), &y) in series.t.iter().zip(&series.measured).zip(&series.model) {
        if t < holdout.0 - 1e-9 || t > holdout.1 + 1e-9 || !(y.is_finite() && m.is_finite()) {
            continue;
        }
        first = first.min(((t - t0) / dt).round() as usize);
        err.push(((m - y) / noise).powi(2));
        sq += (m - y) * (m - y);
    }
    if err.len() < 10 {
        return Err(none());
    }
    let rms = (sq / err.len() as f64).sqrt();
    Ok(HeldOut { err, first, rms })
}

/// A model effect fitted with the nominal gas parameters: its ranking row and its held-out
/// residuals.
pub(super) struct Refit {
    pub entry: RankEntry,
    pub held: Option<HeldOut>,
}

/// Fit `effect` (a model effect) with the gas parameters `free` on `data`, and judge it
/// against the nominal fit's held-out residuals `nominal`.
pub(super) fn refit(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    (free, fit_opts): (&[String], &FitOptions),
    effect: &'static EffectInfo,
    (nominal, holdout): (&HeldOut, (f64, f64)),
    (bootstrap, seed): (usize, u64),
) -> Refit {
    let clock = std::time::Instant::now();
    let mut entry = RankEntry::named(effect.name);
    let strengths: Vec<&str> = effect
        .params
        .iter()
        .filter(|q| q.null.is_some())
        .map(|q| q.name)
        .collect();
    let mut opts = fit_opts.clone();
    let mut all: Vec<String> = free.to_vec();
    all.extend(strengths.iter().map(|s| s.to_string()));
    opts.free = Some(all);
    let fit_from = |p: &[f64], opts: &FitOptions| {
        fit::identify_stages(model, p, data, opts)
            .map_err(DiagnoseError::from)
            .and_then(|(id, _)| held_out(&id, data, holdout).map(|h| (id, h)))
    };
    let fitted = match fit_from(p0, &opts) {
        Ok(first) if at_null(&first.0, &strengths) => {
            // from the typical strength, which is no estimate: no prior pulls it back there
            let mut second = opts.clone();
            second.no_prior = strengths.iter().map(|s| s.to_string()).collect();
            Ok(better(
                first,
                fit_from(&typicals(model, p0, effect), &second),
            ))
        }
        other => other,
    };
    let (id, held) = match fitted {
        Ok(v) => v,
        Err(e) => {
            entry.note = Some(format!("not fitted: {e}"));
            entry.seconds = clock.elapsed().as_secs_f64();
            return Refit { entry, held: None };
        }
    };
    let stage = id.stage2.as_ref().expect("held_out read it");
    // the Wald statistic of the strengths against their nulls (one-sided for one strength:
    // a leak, a friction cannot be negative)
    let mut stat = 0.0;
    for name in &strengths {
        let Some(e) = stage.estimate(name) else {
            continue;
        };
        let z = e.value / e.std_error.max(f64::MIN_POSITIVE);
        stat += if strengths.len() == 1 { z.max(0.0) } else { z }.powi(2);
        let unit = effect
            .params
            .iter()
            .find(|q| q.name == *name)
            .map_or("", |q| q.unit);
        entry.params.push(EffectEstimate {
            name: name.to_string(),
            value: e.value,
            std_error: e.std_error,
            ci_low: e.ci_low,
            ci_high: e.ci_high,
            unit: unit.into(),
        });
        entry.moved |= e.value != 0.0;
    }
    let k = strengths.len();
    entry.score = stat;
    entry.dof = k;
    entry.p_value = if k == 1 {
        0.5 * chi2_sf(stat, 1)
    } else {
        chi2_sf(stat, k)
    };
    entry.fitted = true;
    let n_h = held.err.len() as f64;
    let (e0, e1) = (nominal.mean(), held.mean());
    entry.holdout_error = Some(e1);
    entry.delta_bic = Some(n_h * (e1 / e0).ln() + k as f64 * n_h.ln());
    let c = closure(data, nominal, &held, bootstrap, seed);
    entry.closure_fraction = Some(c.value);
    entry.ci_low = Some(c.ci_low);
    entry.ci_high = Some(c.ci_high);
    entry.note = Some(format!(
        "fitted with the gas parameters by the kinematic fit (Wald test of the strength; p fitted to {:.2} % on the held-out block)",
        stage.fit_percent("p", "holdout").unwrap_or(f64::NAN)
    ));
    entry.seconds = clock.elapsed().as_secs_f64();
    Refit {
        entry,
        held: Some(held),
    }
}

/// Whether every strength of the fit `id` is within one standard error of its null.
fn at_null(id: &Identification, strengths: &[&str]) -> bool {
    let Some(stage) = id.stage2.as_ref() else {
        return false;
    };
    strengths.iter().all(|name| {
        stage
            .estimate(name)
            .is_some_and(|e| e.value.abs() <= e.std_error)
    })
}

/// `p0` with the effect's strengths at their typical values: the second start of a strength
/// the first fit left at its null. Why: a wall's heat capacity has its optimum away from a
/// null where it does not move (the gamma LTD with a 1 J/K hot plate: `kh_hot_plate` fitted
/// from 0 stayed at 2.9e-6 +- 3.5e-2, from the library's 0.04 it came to 1.6 [0.92, 2.28]).
fn typicals(model: &dyn Model, p0: &[f64], effect: &EffectInfo) -> Vec<f64> {
    let mut p = p0.to_vec();
    for q in effect.params.iter().filter(|q| q.null.is_some()) {
        if let Some(j) = model.params().iter().position(|i| i.name == q.name) {
            p[j] = q.typical;
        }
    }
    p
}

/// The first fit, or the second when it fits the training block better.
fn better(
    first: (Identification, HeldOut),
    second: Result<(Identification, HeldOut), DiagnoseError>,
) -> (Identification, HeldOut) {
    let train = |id: &Identification| {
        id.stage2
            .as_ref()
            .and_then(|s| s.fit_percent("p", "train"))
            .unwrap_or(f64::NEG_INFINITY)
    };
    match second {
        Ok(s) if train(&s.0) > train(&first.0) => s,
        _ => first,
    }
}

/// `1 - (err_after - 1)/(err_before - 1)` on the held-out block, with a percentile bootstrap
/// interval over its whole cycles (upward crossings of the pressure's mean).
pub(super) fn closure(
    data: &Measured,
    before: &HeldOut,
    after: &HeldOut,
    count: usize,
    seed: u64,
) -> Interval {
    let n = before.err.len().min(after.err.len());
    let range = (before.first, before.first + n);
    let mut starts: Vec<usize> = cycle_starts(data, range)
        .into_iter()
        .filter(|&s| s >= range.0 && s <= range.1)
        .collect();
    if starts.len() < 3 {
        let len = (n / 10).max(1);
        starts = (range.0..range.1).step_by(len).collect();
    }
    let cycles: Vec<(f64, f64, f64)> = starts
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0] - range.0, w[1] - range.0);
            (
                before.err[a..b].iter().sum::<f64>(),
                after.err[a..b].iter().sum::<f64>(),
                (b - a) as f64,
            )
        })
        .collect();
    let fraction = |pick: &mut dyn Iterator<Item = &(f64, f64, f64)>| {
        let (mut a, mut b, mut n) = (0.0, 0.0, 0.0);
        for c in pick {
            a += c.0;
            b += c.1;
            n += c.2;
        }
        let (eb, ea) = (a / n, b / n);
        1.0 - (ea - 1.0) / (eb - 1.0)
    };
    let value = fraction(&mut cycles.iter());
    let boots: Vec<f64> = resamples(cycles.len(), count, seed)
        .iter()
        .map(|pick| fraction(&mut pick.iter().map(|&i| &cycles[i])))
        .collect();
    let (ci_low, ci_high) = percentile_interval(boots);
    Interval {
        value,
        ci_low,
        ci_high,
    }
}

/// Whether an effect is a model effect (fitted here) rather than a sensor effect.
pub(super) fn is_model_effect(e: &EffectInfo) -> bool {
    e.target == EffectTarget::Model
}
