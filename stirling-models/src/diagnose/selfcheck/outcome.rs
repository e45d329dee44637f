//! One verdict case run: its record, its diagnosis from the case's own perturbed start, and
//! what a user reads of it (the verdict, the leading candidate's closure with its interval).

use std::path::Path;
use std::time::Instant;

use serde::Serialize;
use stirling_dsl::Model;

use super::plan::{named_label, Planned, Split, Truth, VerdictOptions};
use super::record::{record, seeded_start, signature, Signature};
use crate::diagnose::partner;
use crate::diagnose::run::diagnose;
use crate::diagnose::steps::StepRule;
use crate::diagnose::types::{Diagnosis, Evidence, RankEntry};
use crate::diagnose::verdict::{pick, Pick, Thresholds, GROSS_GAP};
use crate::diagnose::DiagnoseError;

/// One case of the verdict self-check.
#[derive(Clone, Debug, Serialize)]
pub struct Outcome {
    pub index: usize,
    pub truth: Truth,
    /// Row label: `clean`, the effect, `outside:NAME`.
    pub label: String,
    pub split: Split,
    pub seed: u64,
    pub perturb_seed: u64,
    /// The diagnosis's own verdict (default thresholds): an effect's name, `unexplained`
    /// or `no_significant_gap`.
    pub verdict: String,
    /// The verdict under the thresholds tuned on the tuning set (filled in by the summary).
    pub tuned_verdict: String,
    /// The right verdict (alternatives joined by ` | `: [`super::plan::is_right`]).
    pub expected: String,
    /// The diagnosis said a gap remains that the named effects do not explain (its verdict
    /// label then ends in [`REMAINDER`](super::plan::REMAINDER)).
    pub remainder: bool,
    /// Candidates the diagnosis considered (the Bonferroni count).
    pub candidates: usize,
    /// The top-ranked candidate and its closure [95 % CI] (the truth's when it is an effect
    /// that was fitted).
    pub top: Option<String>,
    pub closure_of: Option<String>,
    pub closure: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// Rank of the withheld effect (1 = first), if it is a library effect.
    pub truth_rank: Option<usize>,
    /// The first round's ranking (what the thresholds are tuned on).
    pub ranking: Vec<RankEntry>,
    /// The steps of the explanation (what the thresholds re-decide).
    pub steps: Vec<StepBrief>,
    /// The round after the last step, which named nothing (what a step rule is tried on).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub last_round: Vec<RankEntry>,
    /// A second pass's verdict: the one-run pass's candidates and their score p-values.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub one_run: Vec<(String, f64)>,
    /// The nominal model's held-out error (noise variances).
    pub gap: f64,
    pub signature: Signature,
    pub seconds: f64,
    /// Set when the case failed to run (rig or diagnosis error): counted as wrong.
    pub error: Option<String>,
}

/// What the thresholds re-decide of one step of the explanation.
#[derive(Clone, Debug, Serialize)]
pub struct StepBrief {
    pub effects: Vec<String>,
    pub p_value: f64,
    pub delta_bic: f64,
    /// Lower bound of the step's closure of what remained.
    pub ci_low: f64,
    /// Lower bound of the cumulative closure after the step.
    pub cumulative_low: f64,
    /// Named after the stops on the second pass ([`StepRule::at`]).
    pub after_stops: bool,
    /// Named from the reset start ([`StepRule::passes`]).
    pub from_reset: bool,
    /// Named on the one-run pass beside the stops ([`crate::diagnose::partner`]).
    pub one_run: bool,
    /// What named it when not a step's rule: the channels the stops do not touch or the
    /// measured acceleration ([`crate::diagnose::untouched`]).
    pub evidence: Evidence,
    /// Not kept: the joint fit of this step (1 for the first) does not need it
    /// ([`crate::diagnose::superseded`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub superseded_by: Option<usize>,
    /// Held-out error after the step (noise variances) and each channel's rms against its
    /// noise: what a test of the remainder reads.
    pub holdout_error: f64,
    pub channels: Vec<(String, f64)>,
}

/// The verdict label of a diagnosis: the set of named effects (`a+b`, ending in
/// [`REMAINDER`](super::plan::REMAINDER) when the diagnosis says a gap remains), `unexplained` or
/// `no_significant_gap`.
pub fn verdict_label(d: &Diagnosis) -> String {
    if d.verdict.verdict == "effect" && !d.verdict.effects.is_empty() {
        named_label(&d.verdict.effects, d.verdict.unexplained_remainder)
    } else {
        d.verdict.verdict.clone()
    }
}

/// A verdict label from the rule's pick.
pub fn label_of(p: Pick<'_>) -> String {
    match p {
        Pick::Effect(r) => r.effect.clone(),
        Pick::NoSignificantGap => "no_significant_gap".into(),
        Pick::Unexplained => "unexplained".into(),
    }
}

impl Outcome {
    /// The verdict of this case under `th` (an errored case keeps `error`): the steps that
    /// still clear the rule with `th`'s level and BIC bound, named when their cumulative
    /// closure clears `th`'s closure bound; without steps, the first round's pick.
    pub fn relabel(&self, th: &Thresholds) -> String {
        if self.error.is_some() {
            return "error".into();
        }
        if self.steps.is_empty() {
            return label_of(pick(&self.ranking, self.candidates, self.gap, th));
        }
        let level = th.alpha / self.candidates.max(1) as f64;
        let mut named: Vec<(Option<usize>, &String)> = Vec::new();
        let mut cumulative = f64::NEG_INFINITY;
        let mut kept = 0;
        for s in &self.steps {
            let rule = StepRule::at(th.strong_bic, s.after_stops);
            let moved = true;
            let at = (level, s.from_reset);
            let passes = match s.evidence {
                // no threshold of the verdict's decides these: the hinge's share, and the
                // untouched channels' closure bound (the tuned closure bound)
                Evidence::Acceleration => true,
                Evidence::Untouched => s.ci_low > th.min_closure,
                Evidence::Steps if s.one_run => {
                    partner::passes(s.p_value, Some(s.delta_bic), th.strong_bic)
                }
                Evidence::Steps => {
                    rule.passes(moved, s.p_value, Some(s.delta_bic), Some(s.ci_low), at)
                }
            };
            if !passes {
                break;
            }
            named.extend(s.effects.iter().map(|e| (s.superseded_by, e)));
            if s.evidence == Evidence::Steps {
                cumulative = s.cumulative_low;
            }
            kept += 1;
        }
        // end stops named from the acceleration stand without a simulated closure
        let seen = self
            .steps
            .iter()
            .any(|s| s.evidence == Evidence::Acceleration);
        // a step superseded by one the thresholds keep is not named
        let named: Vec<String> = named
            .into_iter()
            .filter(|(by, _)| by.is_none_or(|b| b > kept))
            .map(|(_, e)| e.clone())
            .collect();
        if !named.is_empty() && (seen || cumulative > th.min_closure) {
            named_label(&named, self.remainder)
        } else if self.ranking.iter().any(|r| r.p_value < level) || self.gap > GROSS_GAP {
            "unexplained".into()
        } else {
            "no_significant_gap".into()
        }
    }

    fn blank(c: &Planned) -> Self {
        Outcome {
            index: c.index,
            truth: c.truth.clone(),
            label: c.truth.label(),
            split: c.split,
            seed: c.seed,
            perturb_seed: c.perturb_seed,
            verdict: "error".into(),
            tuned_verdict: "error".into(),
            expected: c.truth.expected(),
            remainder: false,
            candidates: 0,
            top: None,
            closure_of: None,
            closure: None,
            ci_low: None,
            ci_high: None,
            truth_rank: None,
            ranking: Vec::new(),
            one_run: Vec::new(),
            steps: Vec::new(),
            last_round: Vec::new(),
            gap: 0.0,
            signature: Signature::default(),
            seconds: 0.0,
            error: None,
        }
    }

    /// Fill in what the diagnosis says.
    fn read(mut self, d: Diagnosis) -> Self {
        let name = match &self.truth {
            Truth::Effect { name, .. } => Some(name.clone()),
            _ => None,
        };
        self.truth_rank = name
            .as_ref()
            .and_then(|n| d.ranking.iter().position(|r| &r.effect == n).map(|i| i + 1));
        self.remainder = d.verdict.verdict == "effect" && d.verdict.unexplained_remainder;
        self.verdict = verdict_label(&d);
        self.gap = d.verdict.gap;
        self.steps = d
            .steps
            .iter()
            .map(|s| StepBrief {
                effects: s.effects.clone(),
                p_value: s.p_value,
                delta_bic: s.delta_bic,
                ci_low: s.closure.ci_low,
                cumulative_low: s.cumulative.ci_low,
                after_stops: s.after_stops,
                from_reset: s.from_reset,
                one_run: s.one_run,
                evidence: s.evidence,
                superseded_by: s.superseded.as_ref().map(|x| x.by_step),
                holdout_error: s.holdout_error,
                channels: s
                    .channels
                    .iter()
                    .map(|c| (c.channel.clone(), c.ratio))
                    .collect(),
            })
            .collect();
        self.last_round = d.remainder.clone();
        self.tuned_verdict = self.verdict.clone();
        self.top = d.ranking.first().map(|r| r.effect.clone());
        // the closure of the truth when it was fitted, else of the leading candidate
        let entry = name
            .as_ref()
            .and_then(|n| d.ranking.iter().find(|r| &r.effect == n && r.fitted))
            .or_else(|| d.ranking.iter().find(|r| r.fitted));
        self.closure_of = entry.map(|r| r.effect.clone());
        self.closure = entry.and_then(|r| r.closure_fraction);
        self.ci_low = entry.and_then(|r| r.ci_low);
        self.ci_high = entry.and_then(|r| r.ci_high);
        self.candidates = d.ranking.len();
        self.one_run = d
            .one_run
            .iter()
            .map(|r| (r.effect.clone(), r.p_value))
            .collect();
        self.ranking = d.ranking;
        self
    }
}

/// Run case `c`: rig record through a CSV in `dir`, diagnosis from its seeded start. A rig
/// or diagnosis error is kept in the outcome (a wrong case), not returned.
/// The diagnosis's start `p0` as a parameter file (every parameter by name, JSON).
fn write_start(model: &dyn Model, p0: &[f64], path: &Path) -> Result<(), DiagnoseError> {
    let map: serde_json::Map<String, serde_json::Value> = model
        .params()
        .iter()
        .zip(p0)
        .map(|(q, v)| (q.name.to_string(), serde_json::json!(v)))
        .collect();
    let text = serde_json::to_string_pretty(&map).unwrap_or_default();
    std::fs::write(path, text).map_err(|source| DiagnoseError::Io {
        path: path.to_path_buf(),
        source,
    })
}

pub fn run_case(
    opts: &VerdictOptions,
    model: &dyn Model,
    p_nom: &[f64],
    c: &Planned,
    dir: &Path,
) -> Outcome {
    let clock = Instant::now();
    let blank = Outcome::blank(c);
    let attempt = || -> Result<(Diagnosis, Signature), DiagnoseError> {
        let data = record(opts, c, dir)?;
        let sig = signature(&data);
        let p0 = seeded_start(model, p_nom, opts.perturb, c.perturb_seed);
        if opts.records.is_some() {
            write_start(model, &p0, &dir.join(format!("case{}.start.json", c.index)))?;
        }
        Ok((diagnose(model, &p0, &data, &opts.diagnose)?, sig))
    };
    let mut out = match attempt() {
        Ok((d, sig)) => Outcome {
            signature: sig,
            ..blank.read(d)
        },
        Err(e) => Outcome {
            error: Some(e.to_string()),
            ..blank
        },
    };
    out.seconds = clock.elapsed().as_secs_f64();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brief(effect: &str, evidence: Evidence, ci_low: f64, cumulative_low: f64) -> StepBrief {
        StepBrief {
            effects: vec![effect.into()],
            p_value: f64::NAN,
            delta_bic: f64::NAN,
            ci_low,
            cumulative_low,
            after_stops: evidence == Evidence::Untouched,
            from_reset: false,
            one_run: evidence == Evidence::Untouched,
            evidence,
            superseded_by: None,
            holdout_error: f64::NAN,
            channels: Vec::new(),
        }
    }

    fn outcome(steps: Vec<StepBrief>) -> Outcome {
        let mut o = Outcome::blank(&Planned {
            index: 47,
            truth: Truth::Clean,
            split: Split::Eval,
            seed: 1005,
            perturb_seed: 1,
        });
        o.error = None;
        o.candidates = 6;
        o.remainder = true;
        o.steps = steps;
        o
    }

    #[test]
    fn stops_named_from_the_acceleration_and_a_gas_effect_beside_them_keep_their_verdict() {
        // the stops beside a leak: no simulated closure, the leak's closure of the gas
        // channel's gap 0.999 [0.99, 1.0]
        let th = Thresholds::at(0.01);
        let o = outcome(vec![
            brief("end_stops", Evidence::Acceleration, f64::NAN, f64::NAN),
            brief("leak", Evidence::Untouched, 0.99, f64::NAN),
        ]);
        assert_eq!(
            o.relabel(&th),
            named_label(&["end_stops".to_string(), "leak".to_string()], true)
        );
        // a tighter closure bound than the gas channel's closure drops the leak, not the stops
        let tight = Thresholds {
            min_closure: 0.995,
            ..th
        };
        assert_eq!(
            o.relabel(&tight),
            named_label(&["end_stops".to_string()], true)
        );
    }
}
