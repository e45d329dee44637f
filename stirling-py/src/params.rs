//! Parameter dicts: the model's defaults with a dict of values by name, checked as the
//! command line checks `--set` and parameter files (an unknown name lists the valid ones; a
//! value that is not a finite number, or not physical, names the parameter).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_dsl::Model;
use stirling_models::params::{self, ParamError};

/// Where a dict of values comes from, in messages.
const ORIGIN: &str = "params";

/// `base` (default: the model's defaults) with `values` applied by name, validated.
pub fn apply(
    model: &dyn Model,
    base: Option<Vec<f64>>,
    values: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<f64>> {
    let p = apply_unchecked(
        model,
        base.unwrap_or_else(|| model.default_params()),
        values,
    )?;
    params::validate(model, &p).map_err(crate::errors::Failure::from)?;
    Ok(p)
}

/// `p` with `values` applied by name (names and numbers checked, physical ranges not: the
/// diagnosis's starting values, as `stirling diagnose --set` applies them).
pub fn apply_unchecked(
    model: &dyn Model,
    mut p: Vec<f64>,
    values: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<f64>> {
    if let Some(values) = values {
        for (k, v) in values.iter() {
            let name: String = k.str()?.extract()?;
            let i = model
                .param_index(&name)
                .ok_or_else(|| unknown(model, &name))?;
            p[i] = number(&name, &v)?;
        }
    }
    Ok(p)
}

fn unknown(model: &dyn Model, name: &str) -> crate::errors::Failure {
    let valid: Vec<&str> = model.params().iter().map(|p| p.name).collect();
    ParamError::Unknown {
        origin: ORIGIN.into(),
        name: name.into(),
        model: model.name().into(),
        valid: valid.join(", "),
    }
    .into()
}

fn number(name: &str, v: &Bound<'_, PyAny>) -> PyResult<f64> {
    // bools are ints in Python; a parameter is never one
    let ok = !v.is_instance_of::<pyo3::types::PyBool>();
    match v.extract::<f64>() {
        Ok(x) if ok && !x.is_finite() => {
            Err(crate::errors::Failure::from(ParamError::Unphysical {
                name: name.into(),
                value: x,
                why: "must be finite".into(),
            })
            .into())
        }
        Ok(x) if ok => Ok(x),
        _ => Err(crate::errors::Failure::from(ParamError::NotANumber {
            origin: ORIGIN.into(),
            name: name.into(),
            found: v.repr().map(|r| r.to_string()).unwrap_or_default(),
        })
        .into()),
    }
}
