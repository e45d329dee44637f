//! The two-stage identification (mechanics driven by the measured pressure, then the gas
//! driven by the measured positions), optionally refined by multiple shooting, with the
//! free-run validation: estimates, standard errors, 95 % intervals, correlations, fit
//! percentages (`stirling fit`), and the measured-vs-model series.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use stirling_dsl::{Closure, Model};
use stirling_models::fit::{self as library, FitOptions, Series};
use stirling_models::params::ParamError;

use crate::arrays::array1;
use crate::blocks::{blocks, Block};
use crate::convert::to_dict;
use crate::errors::{Failure, Res};
use crate::model::NativeModel;
use crate::record::NativeRecord;
use crate::work;

/// `{name: (lo, hi)}` checked: declared parameters, finite `lo < hi`.
pub fn bounds(
    model: &dyn Model,
    d: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<(String, f64, f64)>> {
    let mut out = Vec::new();
    for (k, v) in d.iter().flat_map(|d| d.iter()) {
        let name: String = k.str()?.extract()?;
        if model.param_index(&name).is_none() {
            let valid: Vec<&str> = model.params().iter().map(|p| p.name).collect();
            return Err(Failure::from(ParamError::Unknown {
                origin: "bounds".into(),
                name,
                model: model.name().into(),
                valid: valid.join(", "),
            })
            .into());
        }
        match v.extract::<(f64, f64)>() {
            Ok((lo, hi)) if lo.is_finite() && hi.is_finite() && lo < hi => out.push((name, lo, hi)),
            _ => {
                return Err(Failure::from(ParamError::Parse {
                    path: "bounds".into(),
                    why: format!(
                    "bounds of `{name}`: expected (lo, hi) with finite numbers lo < hi, found {}",
                    v.repr()?
                ),
                })
                .into())
            }
        }
    }
    Ok(out)
}

fn check_full(model: &dyn Model) -> Res<()> {
    if model.closure() != Closure::Full {
        return Err(Failure::option(format!(
            "the fit runs the full closure (mass states): load `{}` with closure=\"full\"",
            model.name()
        )));
    }
    Ok(())
}

fn series<'py>(py: Python<'py>, s: &[Series]) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for x in s {
        let d = PyDict::new(py);
        d.set_item("channel", &x.channel)?;
        d.set_item("t", array1(py, x.t.clone()))?;
        d.set_item("measured", array1(py, x.measured.clone()))?;
        d.set_item("model", array1(py, x.model.clone()))?;
        out.append(d)?;
    }
    Ok(out)
}

/// Fit `model` (its parameters are the start) to `record`.
#[pyfunction]
#[pyo3(signature = (model, p, record, free=None, bounds=None, train=None, holdout=None, multiple_shooting=None, restart_cycles=None))]
pub fn fit<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    record: &NativeRecord,
    free: Option<Vec<String>>,
    bounds: Option<&Bound<'py, PyDict>>,
    train: Block,
    holdout: Block,
    multiple_shooting: Option<f64>,
    restart_cycles: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model.dyn_model();
    check_full(m)?;
    let p0 = model.params_of(p)?;
    record.check_uniform()?;
    let data = &record.data;
    let (train, holdout) = blocks(train, holdout, data, 0.7)?;
    if let Some(c) = multiple_shooting {
        if !(c.is_finite() && c > 0.0) {
            return Err(Failure::option(format!(
                "multiple_shooting = {c}: a positive number of cycles per segment"
            ))
            .into());
        }
    }
    if let Some(c) = restart_cycles {
        if !(c.is_finite() && c > 0.0 && c <= 1000.0) {
            return Err(Failure::option(format!(
                "restart_cycles = {c}: above 0 and at most 1000 cycles between restarts"
            ))
            .into());
        }
    }
    let opts = FitOptions {
        free,
        restart_cycles,
        bounds: self::bounds(m, bounds)?,
        multiple_shooting: multiple_shooting.map(|c| library::multiple_shooting::MsOptions {
            cycles: c,
            ..Default::default()
        }),
        train,
        holdout,
        ..Default::default()
    };
    let res = work::run(py, None, 0.0, |_| library::identify(m, &p0, data, &opts))?;
    let d = to_dict(py, &res)?;
    let s = PyDict::new(py);
    s.set_item(
        "stage1",
        series(py, res.stage1.as_ref().map_or(&[], |x| &x.series))?,
    )?;
    s.set_item(
        "stage2",
        series(py, res.stage2.as_ref().map_or(&[], |x| &x.series))?,
    )?;
    s.set_item(
        "free_run",
        series(py, res.free_run.as_ref().map_or(&[], |x| &x.series))?,
    )?;
    d.set_item("series", s)?;
    Ok(d)
}
