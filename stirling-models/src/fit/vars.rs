//! The variables of a driven-stage fit (model parameters, initial states, sensor offsets and
//! distortions) and the measured outputs the stage predicts.

use stirling_dsl::Model;

use super::{FitError, FitOptions};

use crate::signal::noise_sigma;

/// Lowest ratio of a positive model parameter to its starting value that a stage simulates.
pub const MIN_RATIO: f64 = 0.02;

/// One fit variable.
#[derive(Clone, Debug)]
pub struct Var {
    pub name: String,
    pub initial: f64,
    pub scale: f64,
    pub kind: VarKind,
    /// A log-normal prior centred on `initial`: `ln(value / initial) / prior` is one more
    /// residual (`None`, or `initial = 0`: no prior). See [`super::FitOptions::prior`].
    pub prior: Option<f64>,
    /// The range the fit keeps it in (a trial step outside is rejected; see
    /// [`super::FitOptions::bounds`]).
    pub bounds: Option<(f64, f64)>,
}

impl Var {
    /// The variables of the model parameters `free` (indices), scaled by their values, with
    /// the options' prior (except on those it names in `no_prior`), in the bounds the
    /// options give (by name) or the model declares.
    pub fn params(model: &dyn Model, p: &[f64], free: &[usize], opts: &FitOptions) -> Vec<Var> {
        free.iter()
            .map(|&j| {
                let name = model.params()[j].name;
                Var {
                    name: name.into(),
                    initial: p[j],
                    scale: p[j].abs().max(1e-12),
                    kind: VarKind::Param(j),
                    prior: opts
                        .prior
                        .filter(|_| !opts.no_prior.iter().any(|n| n == name)),
                    bounds: param_bounds(model, j, &opts.bounds),
                }
            })
            .collect()
    }

    /// The initial value of free state number `pos`.
    pub fn initial(name: &str, initial: f64, scale: f64, pos: usize) -> Var {
        Var {
            name: name.into(),
            initial,
            scale,
            kind: VarKind::Initial(pos),
            prior: None,
            bounds: None,
        }
    }

    /// An additive offset of output `out` that moves the prescribed inputs by `du`.
    pub fn offset(name: &str, initial: f64, scale: f64, out: usize, du: Vec<f64>) -> Var {
        Var {
            name: name.into(),
            initial,
            scale,
            kind: VarKind::Offset { out, du },
            prior: None,
            bounds: None,
        }
    }
}

/// Refuse `value` of parameter `name` outside `bounds` (a trial step the optimizer then
/// shortens).
pub fn check_within(name: &str, value: f64, bounds: Option<(f64, f64)>) -> Result<(), FitError> {
    match bounds.filter(|&(lo, hi)| !(lo..=hi).contains(&value)) {
        Some((lo, hi)) => Err(FitError::OutsideBounds {
            name: name.into(),
            value,
            lo,
            hi,
        }),
        None => Ok(()),
    }
}

/// The bounds of parameter `j`: those `given` name it with, else those the model declares.
pub fn param_bounds(
    model: &dyn Model,
    j: usize,
    given: &[(String, f64, f64)],
) -> Option<(f64, f64)> {
    let name = model.params()[j].name;
    let given = given.iter().find(|b| b.0 == name).map(|b| (b.1, b.2));
    given.or(model.params()[j].bounds)
}

/// What a fit variable is.
#[derive(Clone, Debug)]
pub enum VarKind {
    /// A model parameter.
    Param(usize),
    /// The initial value of free state number `pos`.
    Initial(usize),
    /// An additive offset of output `out`; `du` (per [`Given`](super::sensitivity::Given), may be
    /// empty) is how the prescribed inputs move per unit of the offset.
    Offset { out: usize, du: Vec<f64> },
    /// A sensor distortion (see [`Sensor`]); its column is a central difference of two runs.
    Sensor(Sensor),
    /// A parameter of the gas stage seen by the mechanics stage through the pressure
    /// differences it supplies (records without `p_hot`): prescribed state `g` gains
    /// `(value - at) s(t)` for each `(g, s)` in `pairs`, `s` the signal of `dP_g / dvalue`
    /// at the value `at` the differences were computed at (the first-order link; see
    /// `diagnose::joint`).
    Linked { pairs: Vec<(usize, usize)>, at: f64 },
}

/// A sensor distortion fitted as a variable: the data the stage reads through the sensor as
/// inputs are un-distorted, the model's predictions of what the sensor reads are distorted.
#[derive(Clone, Debug)]
pub enum Sensor {
    /// `measured = (1 + g) true`: the prescribed states `given` (indices into
    /// [`Stage::given`](super::driven::Stage::given)) are divided by `1 + g`, the outputs `outputs`
    /// multiplied by it.
    Gain {
        given: Vec<usize>,
        outputs: Vec<usize>,
    },
    /// `measured = lag(true, tau)` (first order): the input signals `signals` get
    /// `+ tau d/dt` (the inverse lag to first order), the outputs `outputs` are lagged.
    Lag {
        signals: Vec<usize>,
        outputs: Vec<usize>,
    },
}

impl Sensor {
    /// Whether the variable's value cannot be negative (a lag).
    pub fn bounded(&self) -> bool {
        matches!(self, Sensor::Lag { .. })
    }
}

/// A measured output: free state number `pos` plus its offsets.
#[derive(Clone, Debug)]
pub struct Output {
    pub channel: String,
    pub pos: usize,
    pub data: Vec<f64>,
    pub sigma: f64,
}

impl Output {
    /// Output `channel` at free state `pos`, its noise estimated from `data` (at least `floor`).
    pub fn new(channel: &str, pos: usize, data: &[f64], floor: f64) -> Output {
        Output {
            channel: channel.into(),
            pos,
            data: data.to_vec(),
            sigma: noise_sigma(data).max(floor),
        }
    }
}
