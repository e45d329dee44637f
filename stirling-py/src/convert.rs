//! The library's serializable results (what the command line prints with `--json`) as Python
//! dicts and lists, field for field: a result type that gains a field shows it here without
//! a change to the binding. The Python classes of `stirling.results` read them.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;

use crate::errors::{Failure, Kind};

/// `value` as Python objects (structs as dicts, sequences as lists, `None` for absent).
pub fn to_py<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    pythonize::pythonize(py, value).map_err(|e| {
        Failure::new(
            Kind::Internal,
            format!("internal error (please report it): a result could not be converted: {e}"),
        )
        .into()
    })
}

/// `value` as a dict (a struct's fields).
pub fn to_dict<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyDict>> {
    let any = to_py(py, value)?;
    any.cast_into::<PyDict>().map_err(|_| {
        Failure::new(
            Kind::Internal,
            "internal error (please report it): a result is not a record",
        )
        .into()
    })
}
