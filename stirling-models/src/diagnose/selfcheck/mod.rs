//! The self-check. [`run_verdicts`](crate::diagnose::selfcheck::run_verdicts) measures verdicts
//! (issue 15 item 5: effects at two strengths, causes outside the library, clean records,
//! thresholds tuned on one set of seeds and the accuracy counted on another).
//! [`run`](crate::diagnose::selfcheck::run) and
//! [`run_library`](crate::diagnose::selfcheck::run_library), the older rank check: for each effect
//! of the library, rig data with that effect (at one or two strengths) is diagnosed against the
//! nominal model from perturbed starting parameters; the withheld effect must rank first, and data
//! with no added effect must give `no_significant_gap`. The diagnosis sees only the CSV the rig
//! writes (read back from a temporary file), never the truth sidecar.

use std::time::Instant;

use serde::Serialize;
use stirling_dsl::Model;

use super::candidates::nominal_model;
use super::types::Diagnosis;
use super::{DiagnoseError, DiagnoseOptions};

use crate::effects::{effect, effects_for};

/// What the self-check runs.
#[derive(Clone, Debug)]
pub struct SelfCheckOptions {
    pub model: String,
    pub n: Option<usize>,
    /// Effects to withhold (`None`: all that apply).
    pub effects: Option<Vec<String>>,
    /// Strengths as multiples of each effect's typical value.
    pub strengths: Vec<f64>,
    pub t_end: f64,
    pub settle: f64,
    pub rate: f64,
    pub seed: u64,
    /// Relative perturbation of the nominal starting parameters (kd, kp, bd, bp, hh, hk).
    pub perturb: f64,
    pub diagnose: DiagnoseOptions,
    /// Include the clean case (no added effect).
    pub clean: bool,
    /// Channels of the rig records (see [`RigConfig::channels`](crate::rig::RigConfig::channels);
    /// `p_hot` is dropped for a single-CV model).
    pub channels: Vec<String>,
}

impl Default for SelfCheckOptions {
    fn default() -> Self {
        Self {
            model: "cv1".into(),
            n: None,
            effects: None,
            strengths: vec![1.0, 2.0],
            t_end: 2.0,
            settle: 0.1,
            rate: 2000.0,
            seed: 5,
            perturb: 0.08,
            diagnose: DiagnoseOptions::default(),
            clean: true,
            // the hot-side pressure stays in the self-check's records until the diagnosis
            // verdicts are measured on the seed's sensor set (docs/diagnosis.md)
            channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        }
    }
}

/// One case of the self-check.
#[derive(Clone, Debug, Serialize)]
pub struct Case {
    /// The rig's and the diagnosis's model (`cv1`, `nsection n=2`).
    pub model: String,
    /// The withheld effect (`none` for clean data).
    pub truth: String,
    /// Strength as a multiple of the typical value.
    pub strength: f64,
    pub settings: Vec<String>,
    /// `effect` name, `unexplained` or `no_significant_gap`.
    pub verdict: String,
    /// Rank of the withheld effect (1 = first), if it was a candidate.
    pub truth_rank: Option<usize>,
    pub top: Option<String>,
    pub closure_fraction: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// Fitted parameters of the withheld effect (value, interval) vs truth.
    pub fitted: Vec<(String, f64, f64, f64, f64)>,
    /// The verdict is right: the withheld effect's name, or `no_significant_gap` on clean data
    /// (what a user reads; the rank alone is `truth_rank`).
    pub pass: bool,
    pub seconds: f64,
    pub fits: usize,
    #[serde(skip)]
    pub diagnosis: Option<Box<Diagnosis>>,
}

/// The self-check result.
#[derive(Clone, Debug, Serialize)]
pub struct SelfCheck {
    pub model: String,
    pub cases: Vec<Case>,
    /// Labels of rows (truth) and columns (verdict).
    pub labels: Vec<String>,
    /// `matrix[truth][verdict]` counts; the last two columns are `unexplained` and
    /// `no_significant_gap`.
    pub matrix: Vec<Vec<usize>>,
    pub columns: Vec<String>,
    /// Cases whose verdict is right.
    pub passed: usize,
    pub total: usize,
    /// Clean cases and those whose verdict names an effect (false alarms).
    pub clean: usize,
    pub false_alarms: usize,
    pub seconds: f64,
}

/// The self-check's unit strength of an effect, as a multiple of its typical value: Coulomb
/// friction at its typical value stops the default engine (no oscillation left to diagnose);
/// the leak at its typical value barely shows in the driven subsystems; quadratic regenerator
/// friction limits the stroke itself (the limit cycle shrinks until its pressure drop balances
/// the engine's surplus gain), so a strong `Rq` hides its own signature: at 1e9 the stroke is
/// 0.9 mm and the score is not significant on 2 s of data, at 1e8 it is 4.6 mm and the score
/// is 27 (p 1e-7).
pub fn base_strength(name: &str) -> f64 {
    match name {
        "coulomb" => 0.1,
        "leak" => 3.0,
        "regen_quadratic" => 0.1,
        _ => 1.0,
    }
}

/// The verdict self-check's unit strength (on `nsection` n = 2, `p,x,y`), as a multiple of
/// the typical value. One rule for every model effect: the unit moves the record's end
/// stroke by roughly 15 to 50 %, so that twice the unit still leaves an engine that runs (a
/// record without motion is refused, not diagnosed). Coulomb friction at the rank check's
/// unit (0.1) takes 15 % of the stroke and at 2x stops the engine (-99.7 %): the unit is
/// half that. The leak at the rank check's unit (3, `Gleak` 6e-8) takes 80 % of the stroke
/// and 2x leaves almost nothing: the unit is 0.5 (`Gleak` 1e-8, -16 %; 2x -32 %). Quadratic
/// regenerator friction keeps the rank check's unit (-52 %; 2x -67 %). The end stops keep
/// their contact stiffness; a stop is a travel, not a strength, and the verdict check's
/// travels follow the same rule ([`VERDICT_STOPS`], -37 to -44 %).
pub fn verdict_unit(name: &str) -> f64 {
    match name {
        "coulomb" => 0.05,
        "leak" => 0.5,
        _ => base_strength(name),
    }
}

/// Rig settings for an effect at `m` times its verdict self-check unit ([`verdict_unit`]).
pub fn verdict_settings(name: &str, m: f64) -> Vec<String> {
    let mut set = settings(name, m * verdict_unit(name) / base_strength(name));
    if name == "end_stops" {
        // the verdict unit's travels (see [`VERDICT_STOPS`])
        set.retain(|s| !s.starts_with("xmax=") && !s.starts_with("ymax="));
        set.extend(VERDICT_STOPS.map(String::from));
    }
    set
}

/// The end stops' travels in the verdict self-check: 10 mm for the displacer, 5.5 mm for
/// the piston (amplitudes 9.3 mm and 7.6 mm on the clean record), which take 37 % of `x`'s
/// stroke, 40 % of `y`'s and 44 % of `p`'s: inside the 15 to 50 % of every other effect's
/// unit ([`verdict_unit`]). The rank check's travels (2 mm and 1.1 mm) take 87 to 89 %: a
/// second effect beside them leaves almost no trace (a Coulomb friction's score p 0.42, a
/// quadratic regenerator loss's 1.0 after the stops were named), so a pair with them tests
/// the stops alone.
pub const VERDICT_STOPS: [&str; 2] = ["xmax=0.010", "ymax=0.0055"];

/// Rig settings for an effect at `m` times its self-check unit strength.
pub fn settings(name: &str, m: f64) -> Vec<String> {
    let Some(e) = effect(name) else { return vec![] };
    let mut out: Vec<String> = e
        .params
        .iter()
        .filter(|q| q.null.is_some())
        .map(|q| format!("{}={}", q.name, m * base_strength(name) * q.typical))
        .collect();
    if name == "end_stops" {
        // stops inside the recorded stroke, so that they act
        out.push("xmax=0.002".into());
        out.push("ymax=0.0011".into());
    }
    out
}

/// The rig's value of effect parameter `name`: from the settings, else the model default.
fn truth_value(set: &[String], model: &dyn Model, p_nom: &[f64], name: &str) -> f64 {
    set.iter()
        .filter_map(|s| s.split_once('='))
        .find(|(k, _)| *k == name)
        .and_then(|(_, v)| v.parse().ok())
        .or_else(|| model.param_index(name).map(|i| p_nom[i]))
        .unwrap_or(f64::NAN)
}

/// One case: a rig record, its CSV, its diagnosis and what the user reads of it.
mod case;
/// The verdict self-check: running the planned cases in parallel.
mod exec;
/// The verdict self-check: the confusion matrix of verdicts.
pub mod matrix;
/// The verdict self-check: one case's diagnosis and what the user reads of it.
pub mod outcome;
/// The verdict self-check: the case plan (effects, outside causes, clean; tune / eval seeds).
pub mod plan;
/// The verdict self-check: one case's record, signature and perturbed start.
pub mod record;
/// The verdict self-check: Markdown and JSON.
pub mod report;
/// The confusion matrix over the cases.
mod summary;
/// The verdict self-check: thresholds chosen on the tuning seeds.
pub mod tune;
/// The verdict self-check: run, tune, count.
pub mod verdicts;

use case::{measured_channels, perturbed_start, scratch_dir, Bench};
pub use plan::{Split, Truth, VerdictOptions};
pub use summary::matrix_markdown;
use summary::summarize;
pub use verdicts::{run_verdicts, VerdictCheck};

/// Run the self-check.
pub fn run(
    opts: &SelfCheckOptions,
    mut progress: impl FnMut(&Case),
) -> Result<SelfCheck, DiagnoseError> {
    let clock = Instant::now();
    let names: Vec<String> = match &opts.effects {
        Some(v) => v.clone(),
        None => effects_for(&opts.model)
            .iter()
            .map(|e| e.name.to_string())
            .collect(),
    };
    let (model, p_nom) = nominal_model(&opts.model, opts.n)?;
    let label = match opts.n {
        Some(n) => format!("{} n={n}", opts.model),
        None => opts.model.clone(),
    };
    let bench = Bench {
        model: model.as_ref(),
        p_nom: &p_nom,
        p0: perturbed_start(model.as_ref(), &p_nom, opts.perturb),
        channels: measured_channels(model.as_ref(), &opts.channels),
        dir: scratch_dir()?,
        label: label.clone(),
    };
    let mut cases = Vec::new();
    for (k, (truth, strength)) in plan(opts, &names).iter().enumerate() {
        let case = bench.case(opts, k, truth, *strength)?;
        progress(&case);
        cases.push(case);
    }
    let _ = std::fs::remove_dir(&bench.dir);
    Ok(summarize(label, cases, &names, clock))
}

/// The cases: a clean record (when asked), then every effect at every strength.
fn plan(opts: &SelfCheckOptions, names: &[String]) -> Vec<(String, f64)> {
    let clean = opts.clean.then(|| ("none".to_string(), 0.0));
    let withheld = names
        .iter()
        .flat_map(|n| opts.strengths.iter().map(move |&s| (n.clone(), s)));
    clean.into_iter().chain(withheld).collect()
}

/// The self-check of every effect in the library: each on the smallest model it applies to
/// (`cv1`, else `nsection` with two sections), with a clean case on each model used.
/// `opts.model` and `opts.n` are ignored; `opts.effects` filters the library.
pub fn run_library(
    opts: &SelfCheckOptions,
    mut progress: impl FnMut(&Case),
) -> Result<SelfCheck, DiagnoseError> {
    let clock = Instant::now();
    if let Some(bad) = opts.effects.iter().flatten().find(|n| effect(n).is_none()) {
        return Err(DiagnoseError::UnknownEffect {
            name: bad.clone(),
            known: effects_for("nsection")
                .iter()
                .map(|e| e.name)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let wanted = |name: &str| {
        opts.effects
            .as_ref()
            .is_none_or(|v| v.iter().any(|w| w == name))
    };
    let on_cv1: Vec<String> = effects_for("cv1")
        .iter()
        .map(|e| e.name.to_string())
        .filter(|n| wanted(n))
        .collect();
    let on_nsection: Vec<String> = effects_for("nsection")
        .iter()
        .map(|e| e.name.to_string())
        .filter(|n| wanted(n) && !effects_for("cv1").iter().any(|e| e.name == n))
        .collect();
    let mut cases = Vec::new();
    for (model, n, names) in [("cv1", None, &on_cv1), ("nsection", Some(2), &on_nsection)] {
        // a model without effects to check is skipped (cv1 keeps its clean case when
        // nothing else runs)
        if names.is_empty() && !(model == "cv1" && on_nsection.is_empty()) {
            continue;
        }
        let sub = SelfCheckOptions {
            model: model.into(),
            n,
            effects: Some(names.clone()),
            ..opts.clone()
        };
        cases.extend(run(&sub, &mut progress)?.cases);
    }
    let mut names = on_cv1;
    names.extend(on_nsection);
    Ok(summarize("library".into(), cases, &names, clock))
}
