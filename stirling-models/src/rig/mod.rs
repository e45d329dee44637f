//! The virtual test rig: a truth model (the augmented family member with chosen effects),
//! simulated from a perturbed equilibrium, sampled at a rate, passed through the sensor
//! effects (pressure lag, position gain errors), offsets and seeded Gaussian noise.
//!
//! Outputs: `p` (cold-side CV pressure), `p_hot` (hot-side CV pressure, multi-CV models),
//! `x`, `y`. The truth (parameters, effects, seed, noise, offsets) goes to a JSON sidecar.

use std::path::{Path, PathBuf};

use serde::Serialize;
use stirling_dsl::{Closure, Model};

use crate::data::{write_csv_to, Measured};
use crate::effects::{augmented, EffectSettings};
use crate::output::{self, Staged};
use std::io::Write;

/// Why the rig could not run.
mod error;
/// The clean run and the record its sensors give.
mod record;
/// The sensors: lag, gain, offsets, noise.
mod sensors;

pub use error::RigError;
use record::record;

/// What the rig runs.
#[derive(Clone, Debug, Serialize)]
pub struct RigConfig {
    /// Base model (`cv1`, `nsection`, or an alias).
    pub model: String,
    pub n: Option<usize>,
    /// Parameter file of the truth (TOML or JSON by name), applied before `set`.
    pub params: Option<PathBuf>,
    /// Parameter overrides `NAME=VALUE` (model parameters).
    pub set: Vec<String>,
    /// Effect settings `NAME=VALUE` (an effect name sets its strength, or an effect parameter).
    pub effects: Vec<String>,
    /// Record length (s) after settling.
    pub t_end: f64,
    /// Simulated time discarded before the record starts (s).
    pub settle: f64,
    /// Sample rate (Hz).
    pub rate: f64,
    /// Pressure noise standard deviation (Pa).
    pub noise_p: f64,
    /// Position noise standard deviation (m).
    pub noise_x: f64,
    /// Noise standard deviation of named channels, in each channel's unit: overrides
    /// `noise_p`/`noise_x`, and gives the level of a declared sensor in another unit (an
    /// alternator's voltage in V).
    pub noise: Vec<(String, f64)>,
    /// Sensor offsets added to `p` and `p_hot` (Pa), `x`, `y` (m).
    pub offset_p: f64,
    pub offset_x: f64,
    pub offset_y: f64,
    /// Initial displacement of the displacer from rest (m).
    pub x0: f64,
    /// Starting values of states by name, set after the rest state and the `x0` kick: a push
    /// start of a kinematic engine's flywheel (`omega`, rad/s).
    pub start: Vec<(String, f64)>,
    pub seed: u64,
    /// Channels written besides `t` (default: the seed's sensors `p`, `x`, `y`; `p_hot` on
    /// request for multi-CV models).
    pub channels: Vec<String>,
    /// A truth model outside the effect library ([`crate::outside::OUTSIDE`], e.g.
    /// `h_speed`) instead of the augmented family member; its strength is a parameter
    /// (`set`), and it takes no `effects`.
    pub truth: Option<String>,
}

impl RigConfig {
    /// The noise level given for `channel` (`noise`), if any.
    pub fn noise_of(&self, channel: &str) -> Option<f64> {
        self.noise
            .iter()
            .find(|(n, _)| n == channel)
            .map(|&(_, sd)| sd)
    }
}

impl Default for RigConfig {
    fn default() -> Self {
        Self {
            model: "cv1".into(),
            n: None,
            params: None,
            set: Vec::new(),
            effects: Vec::new(),
            t_end: 1.0,
            settle: 0.0,
            rate: 2000.0,
            noise_p: 50.0,
            noise_x: 20e-6,
            noise: Vec::new(),
            offset_p: 0.0,
            offset_x: 0.0,
            offset_y: 0.0,
            x0: 2e-3,
            start: Vec::new(),
            seed: 1,
            channels: vec!["p".into(), "x".into(), "y".into()],
            truth: None,
        }
    }
}

/// The truth sidecar.
#[derive(Clone, Debug, Serialize)]
pub struct Truth {
    /// Augmented model name (e.g. `nsection_fx`) and its base.
    pub model: String,
    pub base: String,
    pub n: usize,
    /// Every parameter of the truth model.
    pub parameters: std::collections::BTreeMap<String, f64>,
    /// Effect settings and the effects switched on.
    pub effects: EffectSettings,
    pub active_effects: Vec<String>,
    /// The outside truth model, when the rig ran one (`--truth`).
    pub outside: Option<String>,
    pub seed: u64,
    pub noise: Noise,
    pub offsets: std::collections::BTreeMap<String, f64>,
    pub rate: f64,
    pub t_end: f64,
    pub settle: f64,
    pub x0: f64,
    /// The states started at given values (`start`).
    pub start: std::collections::BTreeMap<String, f64>,
}

/// Sensor noise levels.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Noise {
    pub p: f64,
    pub x: f64,
}

/// A rig run.
#[derive(Clone, Debug)]
pub struct RigOutput {
    pub data: Measured,
    pub truth: Truth,
}

/// Lowest sample rate the rig accepts (Hz): a kinematic LTD engine turns near 3 Hz and a lab
/// samples it at 100 Hz; the fit refuses a record with fewer than 10 samples per cycle
/// (the family near 13 Hz needs 200 Hz and more for its smoothing derivatives).
pub const MIN_RATE: f64 = 20.0;

/// Check the settings before the (long) simulation.
fn validate(cfg: &RigConfig) -> Result<(), RigError> {
    let bad = |option, got: f64, need: &str| {
        Err(RigError::Setting {
            option,
            got: got.to_string(),
            need: need.into(),
        })
    };
    if !(cfg.t_end > 0.0 && cfg.t_end.is_finite()) {
        return bad("--t-end", cfg.t_end, "a positive number of seconds");
    }
    if !(cfg.settle >= 0.0 && cfg.settle.is_finite()) {
        return bad("--settle", cfg.settle, ">= 0 s");
    }
    if !(cfg.rate >= MIN_RATE && cfg.rate <= 1e6) {
        return bad("--rate", cfg.rate, &format!("between {MIN_RATE} Hz and 1 MHz: the fit needs the engine's cycle resolved (at least 10 samples a cycle)"));
    }
    if cfg.t_end * cfg.rate > 5e6 {
        return Err(RigError::TooManySamples {
            t_end: cfg.t_end,
            rate: cfg.rate,
        });
    }
    for (option, v) in [("--noise-p", cfg.noise_p), ("--noise-x", cfg.noise_x)] {
        if !(v >= 0.0) {
            return bad(option, v, "a non-negative noise level");
        }
    }
    if cfg.channels.is_empty() {
        return Err(RigError::NoChannels);
    }
    for (name, v) in &cfg.start {
        if !v.is_finite() {
            return bad(
                "--start",
                *v,
                &format!("a finite starting value of `{name}`"),
            );
        }
    }
    for (name, v) in &cfg.noise {
        if !cfg.channels.contains(name) {
            return Err(RigError::NoiseChannel {
                channel: name.clone(),
                channels: cfg.channels.join(","),
            });
        }
        if !(*v >= 0.0 && v.is_finite()) {
            return bad(
                "--noise",
                *v,
                &format!("a non-negative noise level for `{name}`"),
            );
        }
    }
    Ok(())
}

/// The engine of `cfg`: the augmented model with its effects and parameters, or the outside
/// truth model with its parameters.
fn engine(cfg: &RigConfig) -> Result<(Box<dyn Model>, EffectSettings, Vec<f64>), RigError> {
    let model = match &cfg.truth {
        Some(t) => outside_engine(cfg, t)?,
        None => augmented(&cfg.model, cfg.n, Closure::Full)?,
    };
    let fx = EffectSettings::parse_for(&cfg.model, Some(model.as_ref()), &cfg.effects)?;
    let mut p = crate::params::load(model.as_ref(), cfg.params.as_deref(), &cfg.set)?;
    fx.apply(model.as_ref(), &mut p)?;
    Ok((model, fx, p))
}

/// The outside truth model `truth` (on `nsection` only; library effects apply to it too, since it
/// extends the augmented engine).
fn outside_engine(cfg: &RigConfig, truth: &str) -> Result<Box<dyn Model>, RigError> {
    crate::outside::outside(truth).ok_or_else(|| {
        RigError::Outside(crate::outside::OutsideError::Unknown {
            name: truth.into(),
            known: crate::outside::OUTSIDE
                .iter()
                .map(|o| o.name)
                .collect::<Vec<_>>()
                .join(", "),
        })
    })?;
    let n = match cfg.model.as_str() {
        "nsection" => cfg.n,
        "order7" => Some(1),
        "order8" => Some(2),
        other => {
            return Err(RigError::TruthBase {
                truth: truth.into(),
                model: other.into(),
            })
        }
    };
    Ok(crate::outside::build(truth, n, Closure::Full)?)
}

/// The truth record: what generated the data.
fn truth(cfg: &RigConfig, model: &dyn Model, p: &[f64], fx: EffectSettings) -> Truth {
    let want = |c: &str| cfg.channels.iter().any(|k| k == c);
    let parameters = crate::params::named(model, p).into_iter().collect();
    let offsets = [
        ("p", cfg.offset_p),
        ("p_hot", cfg.offset_p),
        ("x", cfg.offset_x),
        ("y", cfg.offset_y),
    ]
    .into_iter()
    .filter(|(k, _)| want(k))
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    Truth {
        model: model.name().to_string(),
        base: cfg.model.clone(),
        n: model.n(),
        parameters,
        active_effects: fx.active().into_iter().map(String::from).collect(),
        effects: fx,
        outside: cfg.truth.clone(),
        seed: cfg.seed,
        noise: Noise {
            p: cfg.noise_p,
            x: cfg.noise_x,
        },
        offsets,
        rate: cfg.rate,
        t_end: cfg.t_end,
        settle: cfg.settle,
        x0: cfg.x0,
        start: cfg.start.iter().cloned().collect(),
    }
}

/// Run the rig.
pub fn run(cfg: &RigConfig) -> Result<RigOutput, RigError> {
    validate(cfg)?;
    // a registered model's or an engine file's rig reads its declared sensors; the
    // family's, the seed's four
    let declared =
        crate::model::user_models::find(&cfg.model).is_some() || crate::files::is_file(&cfg.model);
    if !declared {
        check_seed_channels(&cfg.channels)?;
    }
    let (model, fx, p) = engine(cfg)?;
    let data = record(model.as_ref(), &p, &fx, cfg)?;
    let truth = truth(cfg, model.as_ref(), &p, fx);
    Ok(RigOutput { data, truth })
}

/// Measure any model with its declared sensors (`sensor name: STATE "unit";`): the channels
/// `cfg.channels` name (the seed's `p`, `p_hot`, `x`, `y` where the model has them, read as
/// the family's rig reads them, then any other declared sensor), from a run of `model` at
/// `p` with `cfg.effects` (model settings and sensor distortions by name, as the command's
/// `--effect`; an effect the model does not carry is refused). A pressure sensor (unit `Pa`) gets
/// `offset_p` and `noise_p`, a position (`m`) no offset and `noise_x`.
pub fn measure(model: &dyn Model, p: &[f64], cfg: &RigConfig) -> Result<Measured, RigError> {
    // the config's effects act (they were ignored: a lag asked for and a clean record
    // returned): model settings on a copy of `p`, sensor effects on the readings
    let base = model.name().trim_end_matches("_fx");
    let fx = EffectSettings::parse_for(base, Some(model), &cfg.effects)?;
    let mut p = p.to_vec();
    fx.apply(model, &mut p)?;
    measure_with(model, &p, &fx, cfg)
}

/// [`measure`] with the sensor effects of `fx` on the readings (a lag or gain named on a
/// sensor, `tau_<sensor>`, `gain_<sensor>`; the library's `tau_p`, `gain_x`, `gain_y`); its
/// model settings are not applied (set them in `p`).
pub fn measure_with(
    model: &dyn Model,
    p: &[f64],
    fx: &EffectSettings,
    cfg: &RigConfig,
) -> Result<Measured, RigError> {
    validate(cfg)?;
    record(model, p, fx, cfg)
}

/// `--channels` of the family's rig: the seed's four.
fn check_seed_channels(channels: &[String]) -> Result<(), RigError> {
    match channels
        .iter()
        .find(|c| !crate::data::CHANNELS.contains(&c.as_str()))
    {
        Some(c) => Err(RigError::UnknownChannel {
            channel: c.clone(),
            known: crate::data::CHANNELS.join(", "),
        }),
        None => Ok(()),
    }
}

/// A channel's meaning and unit, for the CSV header comment.
fn describe(channel: &str) -> String {
    match channel {
        "p" => "p cold-side pressure [Pa]".into(),
        "p_hot" => "p_hot hot-side pressure [Pa]".into(),
        "x" => "x displacer [m]".into(),
        "y" => "y piston [m]".into(),
        other => format!("{other} (a sensor or a state of the model)"),
    }
}

/// The sidecar path of a CSV: `FILE.truth.json`.
pub fn sidecar_path(csv: &Path) -> PathBuf {
    let mut s = csv.as_os_str().to_owned();
    s.push(".truth.json");
    PathBuf::from(s)
}

/// Write the CSV and its sidecar; refuses to overwrite either unless `force`.
pub fn write(out: &RigOutput, path: &Path, force: bool) -> Result<PathBuf, RigError> {
    let side = sidecar_path(path);
    for f in [path, side.as_path()] {
        if f.exists() && !force {
            return Err(RigError::Exists(f.to_path_buf()));
        }
    }
    let tr = &out.truth;
    let comments = vec![
        format!(
            "stirling rig: truth model {} (n = {}), effects: {}",
            tr.model,
            tr.n,
            if tr.active_effects.is_empty() {
                "none".to_string()
            } else {
                tr.active_effects.join(", ")
            }
        ),
        format!(
            "rate {} Hz, noise p {} Pa, x {} m, seed {}; truth in {}",
            tr.rate,
            tr.noise.p,
            tr.noise.x,
            tr.seed,
            side.display()
        ),
        format!(
            "columns: t [s], {}",
            out.data
                .channels()
                .iter()
                .map(|c| describe(c))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    ];
    // the record and its truth are written whole and published together (crate::output): an
    // interrupted run leaves neither cut, two runs on one path never mix their files
    let mut csv = Staged::new(path, force)?;
    write_csv_to(&mut csv, &out.data, &comments)
        .map_err(|e| RigError::Io(path.to_path_buf(), e))?;
    let json = serde_json::to_string_pretty(&out.truth).expect("serializable");
    let mut truth = Staged::new(&side, force)?;
    truth
        .write_all(json.as_bytes())
        .map_err(|e| RigError::Io(side.clone(), e))?;
    output::commit_all(vec![csv, truth], force)?;
    Ok(side)
}
