//! The sim-to-real gap diagnosis (`stirling diagnose`): the nominal calibration, where the gap
//! lies, which omitted effect explains it and how far it closes, with intervals. The result is
//! the library's `Diagnosis`, field for field (what `--json` prints), so the Python class
//! follows it as it grows.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use stirling_models::diagnose::{self as library, DiagnoseOptions};
use stirling_models::effects::EFFECTS;
use stirling_models::fit::FitOptions;

use crate::blocks::{blocks, Block};
use crate::convert::to_dict;
use crate::errors::{Failure, Res};
use crate::params::apply_unchecked;
use crate::record::NativeRecord;
use crate::work;

fn prior(v: f64) -> Res<Option<f64>> {
    if !v.is_finite() || v < 0.0 {
        return Err(Failure::option(format!(
            "prior = {v}: a finite log standard deviation >= 0 (0: no prior)"
        )));
    }
    Ok((v > 0.0).then_some(v))
}

/// Diagnose `record` against the augmented member of `model` (at `n` sections) with the
/// nominal parameters `params` (by name, over the defaults).
#[pyfunction]
#[pyo3(signature = (model, record, n=None, params=None, effects=None, bounds=None, train=None, holdout=None, prior=library::DEFAULT_PRIOR, fit_all=false, progress=None))]
pub fn diagnose<'py>(
    py: Python<'py>,
    model: &str,
    record: &NativeRecord,
    n: Option<usize>,
    params: Option<&Bound<'py, PyDict>>,
    effects: Option<Vec<String>>,
    bounds: Option<&Bound<'py, PyDict>>,
    train: Block,
    holdout: Block,
    prior: f64,
    fit_all: bool,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    record.check_uniform()?;
    let data = &record.data;
    let (train, holdout) = blocks(train, holdout, data, 0.6)?;
    let (m, p0) = library::nominal_model(model, n).map_err(Failure::from)?;
    let p0 = apply_unchecked(m.as_ref(), p0, params)?;
    let opts = DiagnoseOptions {
        fit: FitOptions {
            bounds: crate::fit::bounds(m.as_ref(), bounds)?,
            ..Default::default()
        },
        effects,
        prior: self::prior(prior)?,
        train,
        holdout,
        progress: progress.map(|_| work::forward_line as fn(&str)),
        fit_all,
        ..Default::default()
    };
    let m = m.as_ref();
    let d = work::run(py, progress, 0.0, |rep| {
        work::with_lines(rep, || library::diagnose(m, &p0, data, &opts))
    })?;
    to_dict(py, &d)
}

/// The effect library: name, summary, parameters (strength first) with their null and typical
/// values and units, and the models whose augmented member carries it.
#[pyfunction]
pub fn effects<'py>(py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for e in EFFECTS {
        let d = PyDict::new(py);
        d.set_item("name", e.name)?;
        d.set_item("summary", e.summary)?;
        let ps = PyList::empty(py);
        for q in e.params {
            let pd = PyDict::new(py);
            pd.set_item("name", q.name)?;
            pd.set_item("null", q.null)?;
            pd.set_item("typical", q.typical)?;
            pd.set_item("unit", q.unit)?;
            ps.append(pd)?;
        }
        d.set_item("params", ps)?;
        d.set_item("applies_to", e.applies_to.to_vec())?;
        out.append(d)?;
    }
    Ok(out)
}
