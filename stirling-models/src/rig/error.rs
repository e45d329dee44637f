//! Why the rig could not run.

use std::path::PathBuf;

/// Why the rig could not run.
#[derive(Debug, thiserror::Error)]
pub enum RigError {
    #[error(transparent)]
    Effect(#[from] crate::effects::EffectError),
    #[error(transparent)]
    Params(#[from] crate::params::ParamError),
    #[error("simulation of the truth model failed: {0}")]
    Sim(#[from] crate::sim::SimError),
    #[error("{option} must be {need} (got {got})")]
    Setting {
        option: &'static str,
        got: String,
        need: String,
    },
    #[error("--t-end {t_end} s at --rate {rate} Hz is {:.0} samples, more than the 5 million the rig writes", t_end * rate)]
    TooManySamples { t_end: f64, rate: f64 },
    #[error("unknown channel `{channel}` in --channels: expected some of {known}")]
    UnknownChannel { channel: String, known: String },
    #[error("sensor `{channel}` is in {unit}: the rig knows the noise of pressures (Pa, --noise-p) and positions (m, --noise-x); give this one's with --noise {channel}=SD (in {unit})")]
    SensorUnit { channel: String, unit: String },
    #[error("--start names `{state}`, which is not a state of `{model}`: its states are {known}")]
    UnknownState {
        state: String,
        model: String,
        known: String,
    },
    #[error("--noise names `{channel}`, which is not among the channels written (--channels {channels})")]
    NoiseChannel { channel: String, channels: String },
    #[error("--channels is empty: name at least one of p, p_hot, x, y")]
    NoChannels,
    #[error("the measured pressure would go negative: its minimum {min:.0} Pa plus --offset-p {offset} minus 5 x --noise-p {noise} is not positive")]
    NegativePressure { min: f64, offset: f64, noise: f64 },
    #[error("`{model}` has no gas volume to measure")]
    NoGas { model: String },
    #[error("channel p_hot asked for, but `{model}` has a single gas volume")]
    NoHotSide { model: String },
    #[error("sensor `{channel}` reads a value that is not a number at t = {t} s (its expression leaves its domain there, e.g. the square root of a negative number)")]
    NonFinite { channel: String, t: f64 },
    #[error(transparent)]
    Outside(#[from] crate::outside::OutsideError),
    #[error("--truth {truth} extends nsection; the model must be nsection (got `{model}`)")]
    TruthBase { truth: String, model: String },
    #[error("`{0}` exists: pass --force to overwrite")]
    Exists(PathBuf),
    #[error("cannot write `{0}`: {1}")]
    Io(PathBuf, std::io::Error),
    #[error(transparent)]
    Output(#[from] crate::output::OutputError),
}
