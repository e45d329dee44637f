//! Library errors to the classes of `stirling.errors` (python/stirling/errors.py), each with
//! the library's message: what went wrong and where. A wrong input raises a class that is also
//! a `ValueError` (`ModelError`, `ParameterError`, `RecordError`, `OptionError`); an analysis
//! that fails on good input raises `SimulationError`, `LinearizationError`, `FitError` or
//! `DiagnosisError` (also `RuntimeError`s). All derive from `StirlingError`.

use pyo3::exceptions::{PyOSError, PyRuntimeError};
use pyo3::prelude::*;
use stirling_models::data::DataError;
use stirling_models::diagnose::DiagnoseError;
use stirling_models::effects::EffectError;
use stirling_models::fit::FitError;
use stirling_models::linear::LinearError;
use stirling_models::params::ParamError;
use stirling_models::rig::RigError;
use stirling_models::sim::SimError;
use stirling_models::sweep::SweepError;
use stirling_models::RegistryError;

/// Which `stirling.errors` class an error raises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Model,
    Parameter,
    Record,
    Option,
    Simulation,
    Linearization,
    Fit,
    Diagnosis,
    Internal,
}

impl Kind {
    fn class(self) -> &'static str {
        match self {
            Kind::Model => "ModelError",
            Kind::Parameter => "ParameterError",
            Kind::Record => "RecordError",
            Kind::Option => "OptionError",
            Kind::Simulation => "SimulationError",
            Kind::Linearization => "LinearizationError",
            Kind::Fit => "FitError",
            Kind::Diagnosis => "DiagnosisError",
            Kind::Internal => "InternalError",
        }
    }
}

/// An error on its way to Python: its class and message.
#[derive(Clone, Debug)]
pub struct Failure {
    pub kind: Kind,
    pub message: String,
}

impl Failure {
    pub fn new(kind: Kind, message: impl Into<String>) -> Self {
        Failure {
            kind,
            message: message.into(),
        }
    }

    /// A wrong argument (shape, value, name) named by the binding itself.
    pub fn option(message: impl Into<String>) -> Self {
        Self::new(Kind::Option, message)
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        Python::attach(|py| {
            let class = py
                .import("stirling.errors")
                .and_then(|m| m.getattr(f.kind.class()));
            match class.and_then(|c| c.call1((f.message.clone(),))) {
                Ok(e) => PyErr::from_value(e),
                // the package's Python half is missing: still raise, with the message
                Err(_) => PyRuntimeError::new_err(f.message),
            }
        })
    }
}

/// A `Result` whose error becomes a `stirling.errors` exception.
pub type Res<T> = Result<T, Failure>;

/// `kind` with the error's own message.
fn with<E: std::fmt::Display>(kind: Kind, e: &E) -> Failure {
    Failure::new(kind, e.to_string())
}

impl From<RegistryError> for Failure {
    fn from(e: RegistryError) -> Self {
        with(Kind::Model, &e)
    }
}

impl From<ParamError> for Failure {
    fn from(e: ParamError) -> Self {
        with(Kind::Parameter, &e)
    }
}

impl From<DataError> for Failure {
    fn from(e: DataError) -> Self {
        with(Kind::Record, &e)
    }
}

impl From<SimError> for Failure {
    fn from(e: SimError) -> Self {
        let kind = match e {
            SimError::DimensionMismatch { .. } | SimError::BadOption(_) => Kind::Option,
            _ => Kind::Simulation,
        };
        with(kind, &e)
    }
}

impl From<LinearError> for Failure {
    fn from(e: LinearError) -> Self {
        let kind = match e {
            LinearError::UnknownChannel { .. }
            | LinearError::NotSinglePressure { .. }
            | LinearError::EmptyRange => Kind::Option,
            LinearError::UnknownParam { .. } | LinearError::Param(_) => Kind::Parameter,
            _ => Kind::Linearization,
        };
        with(kind, &e)
    }
}

/// The class of a fit error: the record's fault, a parameter's, or the fit's.
fn fit_kind(e: &FitError) -> Kind {
    match e {
        FitError::TooFewSamples { .. }
        | FitError::Sampling(_)
        | FitError::NoExcitation { .. }
        | FitError::TooFewCycles { .. }
        | FitError::ShortTraining { .. }
        | FitError::ShortBlock { .. }
        | FitError::BlockCycles { .. }
        | FitError::MissingColumns { .. }
        | FitError::OutsideUnmeasured { .. }
        | FitError::Observe { .. } => Kind::Record,
        FitError::UnknownParameter { .. }
        | FitError::NotInEquations { .. }
        | FitError::OutsideBounds { .. }
        | FitError::BadBounds { .. } => Kind::Parameter,
        _ => Kind::Fit,
    }
}

impl From<FitError> for Failure {
    fn from(e: FitError) -> Self {
        with(fit_kind(&e), &e)
    }
}

fn effect_kind(e: &EffectError) -> Kind {
    match e {
        EffectError::OutOfRange { .. } => Kind::Parameter,
        EffectError::NoAugmented(_) => Kind::Model,
        _ => Kind::Option,
    }
}

impl From<EffectError> for Failure {
    fn from(e: EffectError) -> Self {
        with(effect_kind(&e), &e)
    }
}

impl From<DiagnoseError> for Failure {
    fn from(e: DiagnoseError) -> Self {
        let kind = match &e {
            DiagnoseError::TooFewSamples { .. }
            | DiagnoseError::ShortRecord { .. }
            | DiagnoseError::HoldoutCycles { .. }
            | DiagnoseError::NoMotion { .. }
            | DiagnoseError::MissingChannel { .. }
            | DiagnoseError::Data(_) => Kind::Record,
            DiagnoseError::UnknownEffect { .. }
            | DiagnoseError::NotApplicable { .. }
            | DiagnoseError::BlockOrder { .. } => Kind::Option,
            DiagnoseError::UnknownParameter { .. } => Kind::Parameter,
            DiagnoseError::Effect(x) => effect_kind(x),
            DiagnoseError::Nominal(f) => match fit_kind(f) {
                Kind::Fit => Kind::Diagnosis,
                k => k,
            },
            _ => Kind::Diagnosis,
        };
        with(kind, &e)
    }
}

impl From<RigError> for Failure {
    fn from(e: RigError) -> Self {
        let kind = match &e {
            RigError::Effect(x) => effect_kind(x),
            RigError::Params(_) => Kind::Parameter,
            RigError::Sim(_) | RigError::NonFinite { .. } => Kind::Simulation,
            _ => Kind::Option,
        };
        with(kind, &e)
    }
}

impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Self {
        let kind = match e {
            SweepError::UnknownParameter { .. } | SweepError::Twice { .. } => Kind::Parameter,
            _ => Kind::Option,
        };
        with(kind, &e)
    }
}

/// A file that could not be read or written.
pub fn io(path: &std::path::Path, e: &std::io::Error) -> PyErr {
    PyOSError::new_err(format!("{}: {e}", path.display()))
}
