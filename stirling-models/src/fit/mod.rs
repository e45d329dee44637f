//! Identification from measured data, the seed's two stages (Figures 3-5): stage 1 fits the
//! mechanics driven by the measured pressure, stage 2 the gas model driven by the measured
//! displacements ([`driven`](crate::fit::driven)), each by Levenberg-Marquardt
//! ([`lm`](crate::fit::lm)) on forward sensitivities ([`sensitivity`](crate::fit::sensitivity)),
//! with a statistical report ([`report`](crate::fit::report)).
//!
//! Then, optionally, a multiple-shooting refinement over short free-running segments
//! ([`multiple_shooting`](crate::fit::multiple_shooting)) and a free-run validation from the
//! measured initial state ([`free_run`](crate::fit::free_run)), since a self-excited oscillator
//! drifts in phase.

/// Which free parameter belongs to which stage.
pub mod classify;
/// The two driven subsystems and their stage problem.
pub mod driven;
/// Why a fit failed.
pub mod error;
/// Whether a record moves enough to carry a fit.
pub mod excitation;
/// Free-run validation from the measured initial state.
pub mod free_run;
/// Stage 2: the gas driven by the measured displacements.
pub mod gas;
/// The two-stage identification.
pub mod identify;
/// Errors in variables: noise on the prescribed inputs.
pub mod input_noise;
/// The fit of a kinematic engine: the gas driven by the measured crank angle.
pub mod kinematic;
/// Levenberg-Marquardt.
pub mod lm;
/// The model state and channels a record gives: sensor offsets, measured channels, a state
/// estimated from the smoothed record.
pub mod measured_state;
/// Stage 1: the mechanics driven by the pressures on their faces.
pub mod mechanics;
/// Multiple-shooting refinement over short free-running segments.
pub mod multiple_shooting;
/// The record's channels as outputs of the model (states or declared sensor expressions).
pub mod outputs;
/// Log-normal priors on fitted model parameters.
pub mod prior;
/// The measured record as the stages see it.
pub mod record;
/// Estimates, standard errors, intervals, correlations (statistics, no figures).
pub mod report;
/// Stage runs restarted from the measured state.
pub mod restarts;
/// Forward sensitivities of a driven subsystem.
pub mod sensitivity;
/// Sensor distortions fitted as stage variables.
pub mod sensors;
/// Fitting one driven stage.
pub mod stage_fit;
/// The driven subsystems' sensitivities by the staggered corrector.
pub mod staggered;
/// The static response of the bodies to a pressure offset.
pub mod static_shift;
/// Which declared engines the stages can fit.
pub mod supported;
/// Pressures the mechanics need but the record lacks.
pub mod unmeasured;
/// The variables of a driven-stage fit.
pub mod vars;

use serde::Serialize;

use crate::sim::SimOptions;

pub use classify::{classify, default_free};
pub use identify::{identify, identify_stages};
pub use stage_fit::FittedStage;

pub use error::FitError;
use report::{ChannelFit, FitStats};

/// Options of the two-stage fit.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Free parameters (split by stage automatically); `None`: the defaults
    /// (stage 1 `kd, kp, bd, bp`; stage 2 `hh, hk, Rf` where the model uses them).
    pub free: Option<Vec<String>>,
    /// Training block `[a, b]` (s); default: the first 70 % of the record.
    pub train: Option<(f64, f64)>,
    /// Held-out block; default: the rest of the record.
    pub holdout: Option<(f64, f64)>,
    /// Stage-2 samples skipped at the window start while the gas forgets its initial state (s).
    pub burn_in: f64,
    /// Half-width of the smoothing window for prescribed inputs (s).
    pub smooth: f64,
    pub lm: lm::LmOptions,
    pub sim: SimOptions,
    /// Run stage 1 / stage 2.
    pub stage1: bool,
    pub stage2: bool,
    /// Stage 1: sub-cycle drift band projected out of the residuals, as a fraction of the
    /// cycle frequency (see [`driven::Stage::drift`]; 0: none).
    pub drift_cut: f64,
    /// Monte Carlo draws for the input-noise (errors-in-variables) part of the parameter
    /// covariance (0: skip it; the intervals then miss that part).
    pub input_noise_draws: usize,
    /// Log-normal prior on the free model parameters around their starting values, as a log
    /// standard deviation (see [`prior`]; `None`: plain least squares).
    pub prior: Option<f64>,
    /// Free parameters that carry no prior: their starting values are not estimates (an
    /// effect's strength started at its typical value by the kinematic diagnosis).
    pub no_prior: Vec<String>,
    /// Bounds `(name, lo, hi)` of free parameters, over those the model declares
    /// (`kd: 650.0 "N/m" in 100.0..2000.0`): a trial step outside is rejected, so the fit
    /// stays inside (and the start must be inside).
    pub bounds: Vec<(String, f64, f64)>,
    /// Free-run validation after the stages (on the held-out block, else the training block).
    pub free_run: Option<free_run::FreeRunOptions>,
    /// Multiple-shooting refinement of the free parameters over the training block (off by
    /// default: it costs several times the two stages).
    pub multiple_shooting: Option<multiple_shooting::MsOptions>,
    /// Stage 1 restarted from the measured body states every this many cycles
    /// ([`restarts::Restarts`]; `None`: one run over the block).
    pub restart_cycles: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            free: None,
            train: None,
            holdout: None,
            // the gas's initial temperatures and mass shares are guesses; their transient
            // lasts several thermal time constants (0.03 s left hh/hk 10 % off on nsection n = 2)
            burn_in: 0.2,
            smooth: 0.006,
            lm: lm::LmOptions::stage(),
            sim: SimOptions::default(),
            stage1: true,
            stage2: true,
            drift_cut: 0.5,
            input_noise_draws: 40,
            prior: None,
            no_prior: Vec::new(),
            bounds: Vec::new(),
            free_run: Some(free_run::FreeRunOptions::default()),
            multiple_shooting: None,
            restart_cycles: None,
        }
    }
}

/// Measured and simulated output on the record, for plots.
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    pub channel: String,
    pub t: Vec<f64>,
    pub measured: Vec<f64>,
    pub model: Vec<f64>,
}

/// One stage's result.
#[derive(Clone, Debug, Serialize)]
pub struct StageFit {
    pub stage: String,
    pub stats: FitStats,
    pub fits: Vec<ChannelFit>,
    pub iterations: usize,
    pub evaluations: usize,
    pub converged: bool,
    pub seconds: f64,
    #[serde(skip)]
    pub series: Vec<Series>,
}

impl StageFit {
    /// Fit percentage of a channel on a block (`train` or `holdout`).
    pub fn fit_percent(&self, channel: &str, block: &str) -> Option<f64> {
        self.fits
            .iter()
            .find(|f| f.channel == channel && f.block == block)
            .map(|f| f.fit_percent)
    }
    /// The estimate of a quantity by name.
    pub fn estimate(&self, name: &str) -> Option<&report::Estimate> {
        self.stats.estimates.iter().find(|e| e.name == name)
    }
}

/// The identification result.
#[derive(Clone, Debug, Serialize)]
pub struct Identification {
    pub model: String,
    pub n: usize,
    /// All parameters after the fit.
    pub params: Vec<(String, f64)>,
    pub stage1: Option<StageFit>,
    pub stage2: Option<StageFit>,
    pub train: (f64, f64),
    pub holdout: Option<(f64, f64)>,
    pub seconds: f64,
    /// Sensor offsets after the fit (position offsets as seen by the free model, i.e. with
    /// the stage-2 pressure-offset correction applied).
    pub offsets: free_run::SensorOffsets,
    pub multiple_shooting: Option<multiple_shooting::MultipleShooting>,
    pub free_run: Option<free_run::FreeRun>,
    /// Why an optional step (refinement, free run) did not run.
    pub notes: Vec<String>,
}

impl Identification {
    /// The estimate of a parameter by name, from the stage that fitted it (stage 1 first).
    pub fn estimate(&self, name: &str) -> Option<&report::Estimate> {
        [self.stage1.as_ref(), self.stage2.as_ref()]
            .into_iter()
            .flatten()
            .find_map(|s| s.estimate(name))
    }
}
