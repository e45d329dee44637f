//! Equilibrium, poles and the loop broken at a pressure force (docs/physics.md sections 6-7):
//! the report `stirling linearize --json` prints and the state-space export of `--ss`
//! (python-control reads its `A, B, C, D`), with the Bode and Nyquist data.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_models::linear::{self, export, LinearOptions, NewtonOptions, PoleRequest};

use crate::convert::{to_dict, to_py};
use crate::errors::{Failure, Res};
use crate::model::NativeModel;

/// `"auto"`, `"all"` or a count of dominant poles.
fn request(poles: &Bound<'_, PyAny>) -> Res<PoleRequest> {
    if let Ok(s) = poles.extract::<String>() {
        return match s.as_str() {
            "auto" => Ok(PoleRequest::Auto),
            "all" => Ok(PoleRequest::All),
            _ => Err(Failure::option(format!(
                "poles = `{s}`: expected \"auto\", \"all\" or a count of dominant poles (1 to 200)"
            ))),
        };
    }
    match poles.extract::<usize>() {
        Ok(k) if (1..=200).contains(&k) && !poles.is_instance_of::<pyo3::types::PyBool>() => {
            Ok(PoleRequest::Dominant(k))
        }
        _ => Err(Failure::option(
            "poles: expected \"auto\", \"all\" or a count of dominant poles (1 to 200)",
        )),
    }
}

/// The rest state by Newton on the analytic Jacobian.
#[pyfunction]
pub fn equilibrium<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = model.params_of(p)?;
    let m = model.dyn_model();
    let eq = py
        .detach(|| linear::equilibrium::solve(m, &p, &NewtonOptions::default()))
        .map_err(Failure::from)?;
    to_dict(py, &eq)
}

/// The equilibrium and the dynamic poles (the inventory mode removed).
#[pyfunction]
#[pyo3(signature = (model, p, poles=None))]
pub fn poles<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    poles: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = model.params_of(p)?;
    let req = poles.map(request).transpose()?.unwrap_or_default();
    let m = model.dyn_model();
    let d = py
        .detach(|| linear::dynamic_poles_with(m, &p, &NewtonOptions::default(), req))
        .map_err(Failure::from)?;
    let out = PyDict::new(py);
    out.set_item("equilibrium", to_py(py, &d.equilibrium)?)?;
    out.set_item("poles", to_py(py, &d.poles)?)?;
    out.set_item("route", to_py(py, &d.route)?)?;
    out.set_item("inventory_mode", to_py(py, &d.reduction.inventory)?)?;
    Ok(out)
}

/// The linearization: the report, the state-space export, the Bode and Nyquist data.
#[pyfunction]
#[pyo3(signature = (model, p, channel=None, poles=None))]
pub fn linearize<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    channel: Option<String>,
    poles: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let p = model.params_of(p)?;
    let opts = LinearOptions {
        channel,
        poles: poles.map(request).transpose()?.unwrap_or_default(),
        ..Default::default()
    };
    let m = model.dyn_model();
    let (report, ss, nyquist) = py
        .detach(|| {
            linear::linearize(m, &p, &opts)
                .map(|lin| (lin.report(m), export::export(m, &lin), lin.nyquist()))
        })
        .map_err(Failure::from)?;
    let out = PyDict::new(py);
    out.set_item("report", to_py(py, &report)?)?;
    out.set_item("state_space", to_py(py, &ss)?)?;
    let nq = PyDict::new(py);
    nq.set_item("w", nyquist.w)?;
    nq.set_item("re", nyquist.re)?;
    nq.set_item("im", nyquist.im)?;
    out.set_item("nyquist", nq)?;
    Ok(out)
}
