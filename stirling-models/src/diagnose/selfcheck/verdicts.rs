//! The verdict self-check (issue 15 item 5): the plan run, the thresholds tuned on the
//! tuning seeds, the verdicts on the evaluation seeds counted in a confusion matrix.

use std::time::Instant;

use serde::Serialize;

use super::exec::run_all;
use super::matrix::Confusion;
use super::outcome::Outcome;
use super::plan::{effect_names, plan, Split, Truth, VerdictOptions};
use super::record::Signature;
use super::tune::{tune, Tuned};
use crate::diagnose::candidates::nominal_model;
use crate::diagnose::DiagnoseError;

/// A truth's mean signature against the clean records' (relative changes).
#[derive(Clone, Debug, Serialize)]
pub struct SignatureChange {
    pub label: String,
    pub strength: f64,
    pub x_amp: f64,
    pub y_amp: f64,
    pub p_amp: f64,
    pub freq: f64,
}

/// The verdict self-check's result.
#[derive(Clone, Debug, Serialize)]
pub struct VerdictCheck {
    pub model: String,
    pub channels: Vec<String>,
    pub t_end: f64,
    pub rate: f64,
    pub tuned: Tuned,
    /// Evaluation cases under the tuned thresholds (what the accuracy is reported on).
    pub eval: Confusion,
    /// Evaluation cases under the diagnosis's own (default) thresholds.
    pub eval_default: Confusion,
    /// Tuning cases under the tuned thresholds (not a measure of accuracy).
    pub tune: Confusion,
    /// Each truth's effect on the record: stroke and frequency against the clean records.
    pub signatures: Vec<SignatureChange>,
    pub cases: Vec<Outcome>,
    pub seconds: f64,
    /// Sum of the cases' wall times (s).
    pub case_seconds: f64,
}

/// Run the verdict self-check; `progress` gets every finished case with the count done.
pub fn run_verdicts(
    opts: &VerdictOptions,
    progress: &(dyn Fn(&Outcome, usize, usize) + Sync),
) -> Result<VerdictCheck, DiagnoseError> {
    let clock = Instant::now();
    let cases = plan(opts)?;
    let (model, p_nom) = nominal_model(&opts.model, opts.n)?;
    let outcomes = run_all(opts, model.as_ref(), &p_nom, &cases, progress)?;
    Ok(summarize(opts, outcomes, clock))
}

/// Tune on the tuning cases, relabel every case, count.
pub fn summarize(opts: &VerdictOptions, mut cases: Vec<Outcome>, clock: Instant) -> VerdictCheck {
    let effects = effect_names(opts).unwrap_or_default();
    let tuned = {
        let t: Vec<&Outcome> = cases.iter().filter(|c| c.split == Split::Tune).collect();
        tune(&t, opts.diagnose.alpha)
    };
    for c in &mut cases {
        c.tuned_verdict = c.relabel(&tuned.thresholds);
    }
    let triples = |split: Split, tuned: bool| -> Vec<(String, String, String)> {
        cases
            .iter()
            .filter(|c| c.split == split)
            .map(|c| {
                let v = if tuned { &c.tuned_verdict } else { &c.verdict };
                (c.label.clone(), c.expected.clone(), v.clone())
            })
            .collect()
    };
    let label = match opts.n {
        Some(n) => format!("{} n={n}", opts.model),
        None => opts.model.clone(),
    };
    VerdictCheck {
        model: label,
        channels: opts.channels.clone(),
        t_end: opts.t_end,
        rate: opts.rate,
        eval: Confusion::of(&triples(Split::Eval, true), &effects),
        eval_default: Confusion::of(&triples(Split::Eval, false), &effects),
        tune: Confusion::of(&triples(Split::Tune, true), &effects),
        tuned,
        signatures: signatures(&cases),
        case_seconds: cases.iter().map(|c| c.seconds).sum(),
        cases,
        seconds: clock.elapsed().as_secs_f64(),
    }
}

/// Mean signature of each (truth, strength) relative to the mean of the clean records.
fn signatures(cases: &[Outcome]) -> Vec<SignatureChange> {
    let mean = |sel: &dyn Fn(&Outcome) -> bool, f: &dyn Fn(&Signature) -> f64| {
        let v: Vec<f64> = cases
            .iter()
            .filter(|c| sel(c) && c.error.is_none())
            .map(|c| f(&c.signature))
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let fields: [&dyn Fn(&Signature) -> f64; 4] =
        [&|s| s.x_amp, &|s| s.y_amp, &|s| s.p_amp, &|s| s.freq];
    let clean: Vec<f64> = fields
        .iter()
        .map(|f| mean(&|c| c.truth == Truth::Clean, *f))
        .collect();
    let mut keys: Vec<(String, f64)> = Vec::new();
    for c in cases {
        let k = (c.label.clone(), c.truth.strength());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    keys.into_iter()
        .map(|(label, strength)| {
            let sel = |c: &Outcome| c.label == label && c.truth.strength() == strength;
            let rel: Vec<f64> = fields
                .iter()
                .zip(&clean)
                .map(|(f, c0)| mean(&sel, *f) / c0 - 1.0)
                .collect();
            SignatureChange {
                label,
                strength,
                x_amp: rel[0],
                y_amp: rel[1],
                p_amp: rel[2],
                freq: rel[3],
            }
        })
        .collect()
}
