//! What a diagnosis reports: the gap before, the ranking of the candidate effects, the verdict.

use serde::Serialize;

use super::context::Eval;
use super::{localize, sim_gap};
use crate::effects::EffectInfo;

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
    /// Fitted from the reset start although its score is not significant: a later round on
    /// a calibration that absorbed something ([`super::steps::RESET_P`]).
    pub from_reset: bool,
    /// Beside end stops seen in the measured acceleration, on the one-run pass: its
    /// closure of the held-out gap on the channels the stops do not touch
    /// ([`super::untouched`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub untouched: Option<UntouchedClosure>,
}

/// A candidate's closure of the held-out gap on the channels the seen end stops do not
/// touch ([`super::untouched`]).
#[derive(Clone, Debug, Serialize)]
pub struct UntouchedClosure {
    pub channels: Vec<String>,
    /// Held-out error on those channels, in noise variances, at the nominal calibration and
    /// with the candidate fitted.
    pub before: f64,
    pub after: f64,
    pub closure: Interval,
}

impl RankEntry {
    /// An entry of `effect` before its screen: nothing measured yet.
    pub fn named(effect: &str) -> Self {
        RankEntry {
            effect: effect.into(),
            score: f64::NAN,
            dof: 0,
            p_value: f64::NAN,
            fitted: false,
            delta_bic: None,
            holdout_error: None,
            closure_fraction: None,
            ci_low: None,
            ci_high: None,
            params: Vec::new(),
            note: None,
            seconds: 0.0,
            moved: false,
            from_reset: false,
            untouched: None,
        }
    }
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

/// A fraction with its 95 % interval.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Interval {
    pub value: f64,
    pub ci_low: f64,
    pub ci_high: f64,
}

impl Interval {
    /// No value (not computed).
    pub const NAN: Interval = Interval {
        value: f64::NAN,
        ci_low: f64::NAN,
        ci_high: f64::NAN,
    };
}

/// One step of the explanation: the effect named (or a pair tried together), fitted jointly
/// with the nominal parameters and every effect named before it.
#[derive(Clone, Debug, Serialize)]
pub struct Step {
    /// 1 for the first step.
    pub step: usize,
    /// The effect named at this step (two for a pair tried together).
    pub effects: Vec<String>,
    /// The score p-value of the effect(s) at this step's null (the previous step's fit).
    pub p_value: f64,
    /// Held-out BIC change against the previous step (negative: better).
    pub delta_bic: f64,
    /// Every effect parameter named so far, refitted jointly at this step, 95 % intervals.
    pub params: Vec<EffectEstimate>,
    /// The fraction of the previous step's held-out gap this step closes.
    pub closure: Interval,
    /// The fraction of the nominal model's held-out gap closed after this step.
    pub cumulative: Interval,
    /// Held-out error after this step (noise variances; 1 is the floor).
    pub holdout_error: f64,
    /// Held-out error per channel after this step.
    pub channels: Vec<ChannelError>,
    /// The simulated gap after this step against the calibrated nominal model (features
    /// and residual by phase of the cycle).
    pub simulation_gap: Option<sim_gap::SimulationGap>,
    /// Why the simulated gap is missing, if it is.
    pub simulation_gap_note: Option<String>,
    /// The candidates of this step's round, ranked.
    pub ranking: Vec<RankEntry>,
    pub seconds: f64,
    /// A step after the end stops on the second pass (stage 1 restarted), named under that
    /// pass's rule ([`super::steps::StepRule`]).
    pub after_stops: bool,
    /// Named from the reset start on a calibration that absorbed something, under that
    /// rule ([`super::steps::StepRule::passes`]).
    pub from_reset: bool,
    /// Named on the one-run pass beside end stops seen on the second pass
    /// ([`super::partner`]): its estimates, score and closure are the one-run pass's.
    pub one_run: bool,
    /// What names the step when it is not the rule of the steps (or of a partner):
    /// the channels the seen stops do not touch, or the measured acceleration alone
    /// ([`super::untouched`]).
    pub evidence: Evidence,
    /// Not kept: the last step's joint fit does not need this step's effect
    /// ([`super::superseded`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub superseded: Option<Superseded>,
    /// Residual series after this step, for the report.
    #[serde(skip)]
    pub eval: Option<Eval>,
}

/// What names a step ([`Step::evidence`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Evidence {
    /// The rule of the steps ([`super::steps::StepRule`]) or of a one-run partner
    /// ([`super::partner`]).
    #[default]
    Steps,
    /// Its closure of the gap on the channels the seen end stops do not touch
    /// ([`super::untouched::clears`]).
    Untouched,
    /// End stops seen in the measured acceleration, named without a simulated fit
    /// ([`super::untouched::seen_step`]).
    Acceleration,
}

/// Why a step's effect is not kept in the verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Superseded {
    /// The step whose joint fit does not need it (1 for the first).
    pub by_step: usize,
    pub reason: String,
}

impl Step {
    /// The step's effects as a reader sees them: a partner named from the one-run pass
    /// says so (its closure is of the one-run gap, not of what the last step left).
    pub fn label(&self) -> String {
        let names = self.effects.join(" + ");
        if self.one_run {
            format!("{names} (one-run pass)")
        } else if self.superseded.is_some() {
            format!("{names} (not kept)")
        } else {
            names
        }
    }

    /// A step named on the one-run pass beside end stops (`index`, after `last`): the
    /// entry's one-run estimates, score and BIC change, its `closure`; the cumulative
    /// closure and held-out errors stay the last step's, which a one-run fit does not
    /// change. `note`: why it has no simulated gap of its own.
    pub fn one_run_of(
        e: &RankEntry,
        (last, index): (Option<&Step>, usize),
        closure: Interval,
        note: &str,
    ) -> Step {
        Step {
            step: index,
            closure,
            cumulative: last.map_or(Interval::NAN, |s| s.cumulative),
            holdout_error: last.map_or(f64::NAN, |s| s.holdout_error),
            channels: last.map(|s| s.channels.clone()).unwrap_or_default(),
            simulation_gap_note: Some(note.into()),
            after_stops: true,
            one_run: true,
            ..Step::of_entry(e)
        }
    }

    /// Whether the step carries a simulated closure of the nominal gap (not so for end
    /// stops named from the measured acceleration alone, nor for what is named beside them).
    pub fn has_closure(&self) -> bool {
        self.cumulative.value.is_finite()
    }

    /// What the step closed, of what remained and in all, and the held-out error after it.
    pub fn closure_text(&self) -> String {
        format!(
            "closes {:.2} [{:.2}, {:.2}] of what remained; {:.2} [{:.2}, {:.2}] in all; held-out error {:.3}",
            self.closure.value,
            self.closure.ci_low,
            self.closure.ci_high,
            self.cumulative.value,
            self.cumulative.ci_low,
            self.cumulative.ci_high,
            self.holdout_error,
        )
    }

    /// A step naming the entry `e` alone with its score, BIC change and estimates; no
    /// closure (NaN), no held-out errors, no ranking.
    pub fn of_entry(e: &RankEntry) -> Step {
        Step {
            step: 1,
            effects: vec![e.effect.clone()],
            p_value: e.p_value,
            delta_bic: e.delta_bic.unwrap_or(f64::NAN),
            params: e.params.clone(),
            closure: Interval::NAN,
            cumulative: Interval::NAN,
            holdout_error: f64::NAN,
            channels: Vec::new(),
            simulation_gap: None,
            simulation_gap_note: None,
            ranking: Vec::new(),
            seconds: 0.0,
            after_stops: false,
            from_reset: false,
            one_run: false,
            evidence: Evidence::Steps,
            superseded: None,
            eval: None,
        }
    }
}

/// The verdict.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// `effect`, `unexplained` or `no_significant_gap`.
    pub verdict: String,
    /// The leading effect (for `effect`, the first named; for `unexplained`, the best
    /// candidate tried).
    pub effect: Option<String>,
    /// Every effect named, in the order of the steps (empty unless `effect`).
    pub effects: Vec<String>,
    /// Whether a significant gap remains that the named effects do not explain (always for
    /// `unexplained`, never for `no_significant_gap`).
    pub unexplained_remainder: bool,
    /// Whether the model with the named effects, run on its own over the held-out block, is
    /// further from the record than the calibrated model (its simulated closure's interval
    /// lies below zero, [`crate::diagnose::free_run_check`]): the effects close the gap of the
    /// driven subsystems, not the running engine's.
    pub free_run_worse: bool,
    pub closure_fraction: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// Held-out error of the nominal model in noise variances (1: the noise floor).
    pub gap: f64,
    pub reason: String,
}

/// A candidate's screen and fit.
pub struct Assessed {
    pub entry: RankEntry,
    /// The fitted model's evaluation on the record.
    pub eval: Option<Eval>,
    /// The fit: the joint variables at the optimum, every effect parameter of the problem
    /// (the accepted ones refitted, then the candidate's), the shape setting it started from.
    pub fit: Option<SetFit>,
}

/// The joint fit of a candidate set on a basis.
#[derive(Clone, Debug)]
pub struct SetFit {
    pub effects: Vec<&'static EffectInfo>,
    pub x: Vec<f64>,
    pub params: Vec<EffectEstimate>,
    pub shapes: Vec<(&'static str, f64)>,
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
    /// The first round's candidates (on the nominal calibration), ranked.
    pub ranking: Vec<RankEntry>,
    /// The explanation step by step (empty when no effect closes a significant part).
    pub steps: Vec<Step>,
    /// After the last step, the round that named nothing more, ranked (empty without steps).
    pub remainder: Vec<RankEntry>,
    pub verdict: Verdict,
    /// A kinematic engine's flywheel friction against the file's (`kinematic_flywheel.rs`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flywheel: Option<super::kinematic_flywheel::FlywheelFriction>,
    /// End stops seen in the measured acceleration over the training block
    /// ([`super::stops_equation`]), each body's strongest side (empty: none seen).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub stops_seen: Vec<super::stops_equation::StopSide>,
    /// When the verdict is a second pass's (stage 1 restarted, [`super::restarted`]): the
    /// one-run pass's first round, ranked (empty otherwise). What the restarts cannot show -
    /// an effect that builds up over cycles - shows here.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub one_run: Vec<RankEntry>,
    /// Fits run (the nominal calibration and every joint fit).
    pub fits: usize,
    pub seconds: f64,
    /// Residual series (nominal and winner) on the record, for the report.
    #[serde(skip)]
    pub before: Option<Eval>,
    #[serde(skip)]
    pub after: Option<Eval>,
}
