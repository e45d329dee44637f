//! Why a diagnosis (or one of its candidates, or its self-check) failed.

use std::path::PathBuf;

use crate::data::DataError;
use crate::effects::EffectError;
use crate::fit::FitError;
use crate::rig::RigError;
use crate::sim::SimError;

/// Why a diagnosis failed. A candidate whose joint fit fails does not fail the diagnosis:
/// its error becomes the note of its row in the ranking.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    #[error("{file}: {samples} samples are too few to diagnose (at least {need})")]
    TooFewSamples {
        file: String,
        samples: usize,
        need: usize,
    },
    #[error("the held-out block {}:{} must start after the training block {}:{}", holdout.0, holdout.1, train.0, train.1)]
    BlockOrder {
        train: (f64, f64),
        holdout: (f64, f64),
    },
    #[error("{file}: the record ({seconds:.3} s) is too short to diagnose: the training block (after a {burn_in} s burn-in) and the held-out block need at least {need} samples each; a diagnosis needs a few cycles to fit and a few more to hold out")]
    ShortRecord {
        file: String,
        seconds: f64,
        burn_in: f64,
        need: usize,
    },
    #[error("{file}: the held-out block {from:.3}:{to:.3} s holds fewer than two cycles: too few to hold out (a longer record, or --train/--holdout)")]
    HoldoutCycles { file: String, from: f64, to: f64 },
    #[error("{file}: the motion dies out: over the held-out block {from:.3}:{to:.3} s channel `{channel}` varies by {rms:.3e} rms against a noise of {noise:.3e} (at least {need}x the noise is needed to read a cycle); the engine has stopped, so there is no cycle to diagnose (diagnose the part of the record where it runs, with --train/--holdout)")]
    NoMotion {
        file: String,
        from: f64,
        to: f64,
        channel: &'static str,
        rms: f64,
        noise: f64,
        need: f64,
    },
    #[error("unknown effect `{name}`: expected one of {known}")]
    UnknownEffect { name: String, known: String },
    #[error("the self-check's evaluation set is empty (no evaluation seed and no clean evaluation record): give --seeds TUNE:EVAL or --clean TUNE:EVAL with EVAL >= 1")]
    EmptyEvaluation,
    #[error("the self-check has no case `{label}` (--cases): its cases are {known}")]
    UnknownCase { label: String, known: String },
    #[error("effect `{name}` is named twice in the candidates: name each once")]
    DuplicateEffect { name: String },
    #[error("effect `{effect}` does not apply to `{model}` (it applies to {applies})")]
    NotApplicable {
        effect: String,
        model: String,
        applies: String,
    },
    #[error(transparent)]
    Effect(#[from] EffectError),
    // the cause in the message, not as a source: a chain printed by the caller showed it twice
    #[error("the nominal calibration failed: {0}")]
    Nominal(FitError),
    #[error("model `{model}` is a kinematic engine: its diagnosis calibrates the gas parameters driven by the measured angle, and it has no film coefficient (W/(m^2 K)) to free by default: name the gas parameters to calibrate with --free")]
    KinematicFree { model: String },
    // the fit's refusal of a kinematic record (its rate), as the fit words it
    #[error("{0}")]
    Record(FitError),
    #[error("model `{model}` has no parameter `{name}`")]
    UnknownParameter { name: String, model: String },
    #[error("`{param}` enters neither driven subsystem of `{model}`")]
    NotDriven { param: String, model: String },
    #[error("sensor parameter `{name}` is not handled by the diagnosis")]
    SensorParam { name: String },
    #[error("{file}: channel `{channel}` is missing")]
    MissingChannel { file: String, channel: String },
    #[error("the calibration produced no output series")]
    NoOutputs,
    #[error("no model output for `{channel}` at sample {sample}")]
    NoModelOutput { channel: String, sample: usize },
    #[error("the joint fit could not evaluate its start")]
    JointStart,
    #[error("the joint fit did not settle its bounds")]
    JointBounds,
    #[error("`{model}` has no pressure state")]
    NoPressure { model: String },
    #[error("{stage}: simulation failed: {source}")]
    Sim {
        stage: &'static str,
        #[source]
        source: SimError,
    },
    #[error("{stage} needs the columns x and y")]
    NeedsPositions { stage: &'static str },
    #[error("rig ({truth}): {source}")]
    Rig {
        truth: String,
        #[source]
        source: RigError,
    },
    #[error(transparent)]
    Data(#[from] DataError),
    #[error("cannot write `{}`: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl From<FitError> for DiagnoseError {
    fn from(e: FitError) -> Self {
        DiagnoseError::Nominal(e)
    }
}
