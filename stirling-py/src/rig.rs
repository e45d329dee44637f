//! The virtual test rig: a truth model (the family member with the effects named, or a cause
//! outside the library) run with sensor noise, offsets and lags, sampled into a record, with
//! the truth beside it (`stirling rig`).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_models::params::ParamError;
use stirling_models::rig::{self as library, RigConfig};

use crate::convert::to_dict;
use crate::errors::Failure;
use crate::record::NativeRecord;
use crate::work;

/// `{name: value}` as the rig's `NAME=VALUE` settings (`origin` names the argument).
fn settings(d: Option<&Bound<'_, PyDict>>, origin: &str) -> PyResult<Vec<String>> {
    let mut out = Vec::new();
    for (k, v) in d.iter().flat_map(|d| d.iter()) {
        let name: String = k.str()?.extract()?;
        let is_bool = v.is_instance_of::<pyo3::types::PyBool>();
        let value = match v.extract::<f64>() {
            Ok(x) if !is_bool => x,
            _ => {
                return Err(Failure::from(ParamError::NotANumber {
                    origin: origin.into(),
                    name,
                    found: v.repr().map(|r| r.to_string()).unwrap_or_default(),
                })
                .into())
            }
        };
        // `{:?}` writes the shortest text that reads back as the same f64
        out.push(format!("{name}={value:?}"));
    }
    Ok(out)
}

fn noise(d: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<(String, f64)>> {
    let mut out = Vec::new();
    for s in settings(d, "noise")? {
        if let Some((n, v)) = s.split_once('=') {
            out.push((n.to_string(), v.parse().unwrap_or(f64::NAN)));
        }
    }
    Ok(out)
}

/// Run the rig; returns the record and the truth (model, parameters, effects, noise, offsets).
#[pyfunction]
#[pyo3(signature = (model, n=None, params=None, effects=None, truth=None, t_end=1.0, settle=0.0, rate=2000.0, noise_p=50.0, noise_x=20e-6, noise=None, offset_p=0.0, offset_x=0.0, offset_y=0.0, x0=2e-3, seed=1, channels=None))]
pub fn rig<'py>(
    py: Python<'py>,
    model: String,
    n: Option<usize>,
    params: Option<&Bound<'py, PyDict>>,
    effects: Option<&Bound<'py, PyDict>>,
    truth: Option<String>,
    t_end: f64,
    settle: f64,
    rate: f64,
    noise_p: f64,
    noise_x: f64,
    noise: Option<&Bound<'py, PyDict>>,
    offset_p: f64,
    offset_x: f64,
    offset_y: f64,
    x0: f64,
    seed: u64,
    channels: Option<Vec<String>>,
) -> PyResult<(NativeRecord, Bound<'py, PyDict>)> {
    let cfg = RigConfig {
        model,
        n,
        params: None,
        set: settings(params, "params")?,
        effects: settings(effects, "effects")?,
        t_end,
        settle,
        rate,
        noise_p,
        noise_x,
        noise: self::noise(noise)?,
        offset_p,
        offset_x,
        offset_y,
        x0,
        start: Vec::new(),
        seed,
        channels: channels.unwrap_or_else(|| RigConfig::default().channels),
        truth,
    };
    let out = work::run(py, None, 0.0, |_| library::run(&cfg).map_err(Failure::from))?;
    let truth = to_dict(py, &out.truth)?;
    Ok((NativeRecord::plain(out.data), truth))
}
