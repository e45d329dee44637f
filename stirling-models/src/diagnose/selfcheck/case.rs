//! One self-check case: a rig record with the effect withheld, written to CSV and read back
//! like any measured file, diagnosed from a perturbed start, and read against the truth.

use std::path::PathBuf;
use std::time::Instant;

use stirling_dsl::Model;

use super::{settings, truth_value, Case, SelfCheckOptions};
use crate::diagnose::run::diagnose;
use crate::diagnose::types::Diagnosis;
use crate::diagnose::DiagnoseError;
use crate::rig::{self, RigConfig};

/// The diagnosis's start: the rig's parameters with the stiffnesses, dampings and heat
/// transfer moved by about `perturb` (alternating signs), as a user's first guess would be.
pub(super) fn perturbed_start(model: &dyn Model, p_nom: &[f64], perturb: f64) -> Vec<f64> {
    let mut p0 = p_nom.to_vec();
    let moved = [
        ("kd", 1.0),
        ("kp", -1.0),
        ("bd", 1.0),
        ("bp", -1.0),
        ("hh", 1.0),
        ("hk", -1.0),
    ];
    for (k, (name, sign)) in moved.iter().enumerate() {
        if let Some(i) = model.param_index(name) {
            p0[i] *= 1.0 + sign * perturb * (1.0 - 0.1 * k as f64);
        }
    }
    p0
}

/// The channels the rig writes: `p_hot` only where the model has a hot side (more than one
/// CV).
pub(super) fn measured_channels(model: &dyn Model, asked: &[String]) -> Vec<String> {
    let multi_cv = crate::layout::StateLayout::of(model).pressures.len() > 1;
    asked
        .iter()
        .filter(|c| multi_cv || c.as_str() != "p_hot")
        .cloned()
        .collect()
}

/// One folder per run: self-checks may run concurrently in one process (tests).
pub(super) fn scratch_dir() -> Result<PathBuf, DiagnoseError> {
    static RUNS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let run = RUNS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("stirling-selfcheck-{}-{run}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|source| DiagnoseError::Io {
        path: dir.clone(),
        source,
    })?;
    Ok(dir)
}

/// What every case of one self-check shares.
pub(super) struct Bench<'a> {
    pub model: &'a dyn Model,
    pub p_nom: &'a [f64],
    pub p0: Vec<f64>,
    pub channels: Vec<String>,
    pub dir: PathBuf,
    pub label: String,
}

impl Bench<'_> {
    /// Case `k`: a rig record with `truth` at `strength`, written to CSV and read back like
    /// any measured file (only the CSV crosses over), then diagnosed from the perturbed start.
    pub fn case(
        &self,
        opts: &SelfCheckOptions,
        k: usize,
        truth: &str,
        strength: f64,
    ) -> Result<Case, DiagnoseError> {
        let t = Instant::now();
        let set = if truth == "none" {
            vec![]
        } else {
            settings(truth, strength)
        };
        let cfg = RigConfig {
            model: opts.model.clone(),
            n: opts.n,
            effects: set.clone(),
            t_end: opts.t_end,
            settle: opts.settle,
            rate: opts.rate,
            seed: opts.seed + k as u64,
            channels: self.channels.clone(),
            ..Default::default()
        };
        let out = rig::run(&cfg).map_err(|source| DiagnoseError::Rig {
            truth: truth.to_string(),
            source,
        })?;
        let data = super::record::through_csv(out, &self.dir, k, false)?;
        let d = diagnose(self.model, &self.p0, &data, &opts.diagnose)?;
        let mut case = self.read_case(d, truth, strength, set);
        case.seconds = t.elapsed().as_secs_f64();
        Ok(case)
    }

    /// What the user reads of one case's diagnosis, against the truth.
    fn read_case(&self, d: Diagnosis, truth: &str, strength: f64, set: Vec<String>) -> Case {
        let truth_rank = d
            .ranking
            .iter()
            .position(|r| r.effect == truth)
            .map(|i| i + 1);
        let verdict = super::outcome::verdict_label(&d);
        let entry = d.ranking.iter().find(|r| r.effect == truth);
        let fitted = entry
            .map(|r| {
                r.params
                    .iter()
                    .map(|q| {
                        let tv = truth_value(&set, self.model, self.p_nom, &q.name);
                        (q.name.clone(), tv, q.value, q.ci_low, q.ci_high)
                    })
                    .collect()
            })
            .unwrap_or_default();
        let pass = if truth == "none" {
            verdict == "no_significant_gap"
        } else {
            verdict == truth
        };
        Case {
            model: self.label.clone(),
            truth: truth.to_string(),
            strength,
            settings: set,
            verdict,
            truth_rank,
            top: d.ranking.first().map(|r| r.effect.clone()),
            closure_fraction: entry.and_then(|r| r.closure_fraction),
            ci_low: entry.and_then(|r| r.ci_low),
            ci_high: entry.and_then(|r| r.ci_high),
            fitted,
            pass,
            seconds: 0.0,
            fits: d.fits,
            diagnosis: Some(Box::new(d)),
        }
    }
}
