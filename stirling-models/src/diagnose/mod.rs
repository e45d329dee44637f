//! The sim-to-real gap diagnosis (method and results: docs/diagnosis.md):
//! calibrate the nominal model on a training block with the two driven subsystems
//! ([`crate::fit`]), then
//! - **where** ([`localize`](crate::diagnose::localize)): residuals per channel, per harmonic of
//!   the cycle, per phase of the cycle, per subsystem (stage-1 mechanics vs stage-2 gas), and
//!   limit-cycle features of the measured record against a free run of the calibrated model;
//! - **which** ([`score`](crate::diagnose::score)): a robust score (Lagrange-multiplier) test of
//!   every candidate effect at its null, from one Jacobian of the joint problem
//!   ([`joint`](crate::diagnose::joint): the calibrated stages the effect touches, extended by its
//!   variables);
//! - fit the significant candidates jointly with the nominal variables of those stages and rank
//!   them by held-out error with a BIC penalty ([`rank`](crate::diagnose::rank));
//! - **how far** ([`closure`](crate::diagnose::closure)): the fraction of the held-out excess error
//!   closed by the winner, with a bootstrap interval over whole cycles; the
//!   [`verdict`](crate::diagnose::verdict);
//! - **the gap a user sees** ([`sim_gap`](crate::diagnose::sim_gap)): the calibrated model
//!   simulated on its own over the held-out block, feature by feature (frequency, amplitudes,
//!   phase, work, growth), before and after the leading effect, with intervals and one summary
//!   closure.

/// One round of candidates on a basis: screen, fit, rank, close.
mod assess;
mod blocks;
mod candidates;
/// How far: the closed fraction of the held-out gap with a bootstrap interval over cycles.
pub mod closure;
/// The record, its blocks and noise, and the residuals of a model on it.
pub mod context;
/// The diagonal of the Gauss-Newton covariance.
pub mod covariance;
/// Per-cycle features and waveforms by phase of the cycle.
mod cycle_features;
/// Why a diagnosis failed.
pub mod error;
/// The free run of the named effects, checked against the calibrated model's.
pub mod free_run_check;
mod gap;
/// The joint problem of one candidate: the calibrated stages extended by its variables.
pub mod joint;
/// The joint fit of one candidate from one start.
mod joint_fit;
/// The diagnosis of a kinematic engine: the driven stage of the measured angle.
pub mod kinematic;
/// A kinematic engine's flywheel friction against the file's.
pub mod kinematic_flywheel;
/// The model effects of a kinematic engine, fitted by the kinematic fit.
mod kinematic_refit;
mod kinematic_verdict;
/// Where: residuals by channel, harmonic, phase of the cycle and subsystem.
pub mod localize;
/// Pairs of significant candidates tried together.
mod pairs;
/// A partner beside seen end stops, named from the one-run pass.
pub mod partner;
/// Which: fit and rank the screened candidates.
pub mod rank;
/// The Markdown report and its figures.
pub mod report;
/// The second pass for end stops, with stage 1 restarted.
pub mod restarted;
mod run;
mod schedule;
/// The robust score test of an effect at its null.
pub mod score;
/// The score screen of one candidate at the effect's null.
pub mod screen;
/// The self-check on rig records whose effect is withheld.
pub mod selfcheck;
/// The simulated gap: held-out cycle features of the free run, before and after.
pub mod sim_gap;
/// The explanation step by step.
pub mod steps;
/// End stops seen in the measured acceleration (equation error).
pub mod stops_equation;
/// The backward check: an earlier step's effect the last step's fit does not need.
pub mod superseded;
/// What a diagnosis reports.
pub mod types;
/// An effect beside seen end stops, judged on the channels the stops do not touch.
pub mod untouched;
/// The verdict a user reads.
pub mod verdict;

pub use candidates::nominal_model;
pub use context::{Context, Eval, Prediction};
pub use error::DiagnoseError;
pub use run::diagnose;
pub use types::{
    ChannelError, Diagnosis, EffectEstimate, GapBefore, Interval, ParamShift, RankEntry, Step,
};

use crate::fit::FitOptions;

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
    /// Relative (and absolute, on the scaled states) tolerance of every driven run of a
    /// free-piston diagnosis, in place of `fit.sim`'s ([`DIAGNOSE_RTOL`]).
    pub rtol: f64,
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
    /// Fit every candidate, not only those whose score is significant (slower; the verdict
    /// is the same, the ranking of the non-significant candidates is filled in).
    pub fit_all: bool,
    /// Called with a line of progress after the calibration and after each candidate
    /// (`None`: silent).
    pub progress: Option<fn(&str)>,
}

/// The diagnosis's integration tolerance: 5x the fit's default (1e-7), which halves the
/// steps of every driven run. Against runs at 1e-9, the nominal calibration's estimates moved
/// by at most 0.017, 0.14 and 0.01 standard errors on three records (quadratic friction with a
/// lag, Coulomb friction, position gains: docs/diagnosis.md, "Timing of the steps"), against
/// 0.007, 0.09 and 0.002 at 1e-7; at 1e-6 the Coulomb record's pressure offset moved by 9.8.
pub const DIAGNOSE_RTOL: f64 = 5e-7;

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
            rtol: DIAGNOSE_RTOL,
            noise_draws: 40,
            bootstrap: 400,
            alpha: 0.01,
            seed: 7,
            progress: None,
            fit_all: false,
            prior: Some(DEFAULT_PRIOR),
        }
    }
}
