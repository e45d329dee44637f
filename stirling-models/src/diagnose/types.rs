//! What a diagnosis reports: the gap before, the ranking of the candidate effects, the verdict.

use serde::Serialize;

use super::context::Eval;
use super::{localize, sim_gap, verdict};

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
    /// BIC change on the held-out block plus the change of the nominal parameters' prior cost
    /// (negative: better than the nominal model; see [`rank`](super::rank)).
    pub delta_bic: Option<f64>,
    pub holdout_error: Option<f64>,
    pub closure_fraction: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// Fitted effect parameters with 95 % intervals.
    pub params: Vec<EffectEstimate>,
    /// Why it could not be screened or fitted, if so.
    pub note: Option<String>,
    /// Time spent screening and fitting this candidate (s).
    pub seconds: f64,
    /// The fit moved a strength off its null (else it is the nominal model again).
    #[serde(skip)]
    pub moved: bool,
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
    /// The gap where a user sees it: the calibrated model simulated on its own over the
    /// held-out block, feature by feature, before and after the leading effect.
    pub simulation_gap: Option<sim_gap::SimulationGap>,
    /// Why the simulated gap is missing, if it is.
    pub simulation_gap_note: Option<String>,
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
