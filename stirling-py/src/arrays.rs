//! numpy arrays in and out. An input is any sequence of numbers numpy reads as floats (a
//! float64 array is taken without copying); a wrong shape or a value that is not finite is an
//! `OptionError` that names the argument, its expected shape and the first bad entry.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::errors::{Failure, Res};

/// `obj` as a vector of floats (`what` names it in errors); `len`: the length it must have,
/// with `of` saying what the entries are (`"states of `schmidt`"`).
pub fn vector(
    obj: &Bound<'_, PyAny>,
    what: &str,
    len: Option<(usize, &str)>,
) -> PyResult<Vec<f64>> {
    let v = match obj.extract::<PyReadonlyArray1<'_, f64>>() {
        Ok(a) => a.as_array().to_vec(),
        Err(_) => as_float_array(obj, what)?,
    };
    if let Some((n, of)) = len {
        if v.len() != n {
            return Err(Failure::option(format!(
                "{what} has {} entries; it must have {n} ({of})",
                v.len()
            ))
            .into());
        }
    }
    finite(&v, what)?;
    Ok(v)
}

/// Through `numpy.asarray(obj, dtype=float)`: nested sequences, integer arrays, scalars
/// refused with their shape.
fn as_float_array(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np
        .call_method1("asarray", (obj, np.getattr("float64")?))
        .map_err(|e| {
            Failure::option(format!(
                "{what} must be a sequence of numbers: {}",
                e.value(py)
            ))
        })?;
    let shape: Vec<usize> = arr.getattr("shape")?.extract()?;
    if shape.len() != 1 {
        return Err(Failure::option(format!(
            "{what} must be one-dimensional, got an array of shape {}",
            shape_text(&shape)
        ))
        .into());
    }
    let a = arr.extract::<PyReadonlyArray1<'_, f64>>()?;
    Ok(a.as_array().to_vec())
}

/// `(3,)`, `(2, 2)`, as numpy prints a shape.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Every entry finite, or an error naming the first that is not.
pub fn finite(v: &[f64], what: &str) -> Res<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Failure::option(format!(
            "{what}[{i}] = {} is not a finite number",
            v[i]
        ))),
    }
}

/// A vector as a numpy array.
pub fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyArray1<f64>> {
    v.into_pyarray(py)
}

/// Rows of equal length as a 2-D array (`cols` columns when there are no rows).
pub fn array2<'py>(py: Python<'py>, rows: &[Vec<f64>], cols: usize) -> Bound<'py, PyArray2<f64>> {
    let ncols = rows.first().map_or(cols, |r| r.len());
    let flat: Vec<f64> = rows.iter().flat_map(|r| r.iter().copied()).collect();
    let a = Array2::from_shape_vec((rows.len(), ncols), flat)
        .unwrap_or_else(|_| Array2::zeros((0, ncols)));
    a.into_pyarray(py)
}

/// A column-major `nrows x ncols` matrix (as the models write Jacobians) as a 2-D array.
pub fn col_major<'py>(
    py: Python<'py>,
    data: Vec<f64>,
    nrows: usize,
    ncols: usize,
) -> Bound<'py, PyArray2<f64>> {
    let a = Array2::from_shape_vec((ncols, nrows), data)
        .map(|a| a.reversed_axes())
        .unwrap_or_else(|_| Array2::zeros((nrows, ncols)));
    a.into_pyarray(py)
}

/// Complex numbers `(re, im)` as a numpy complex array.
pub fn complex<'py>(
    py: Python<'py>,
    z: impl Iterator<Item = (f64, f64)>,
) -> Bound<'py, PyArray1<numpy::Complex64>> {
    let v: Vec<numpy::Complex64> = z.map(|(re, im)| numpy::Complex64::new(re, im)).collect();
    v.into_pyarray(py)
}
