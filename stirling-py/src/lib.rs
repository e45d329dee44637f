//! The native half of the Python module `stirling` (`stirling._native`): thin functions over
//! `stirling-models` that take numpy arrays and Python dicts and return them. The public
//! Python API (typed result classes, docstrings with units, progress bars) is the pure-Python
//! package in `python/stirling/`; docs/python.md is the guide.
//!
//! Everything here needs the `python` feature (maturin turns it on); without it the crate is
//! empty, so `cargo test --workspace` neither builds nor links PyO3.
//!
//! - `model`: a model of the family (or a registered one) by name; states, parameters,
//!   sensors, equations, the right-hand side and its Jacobians.
//! - `params`: parameter dicts to the model's vector, checked as the command line checks them.
//! - `linear`, `simulate`, `cycle`: equilibrium, poles, the broken loop and its margins; runs;
//!   limit cycles with Floquet multipliers and cycle work.
//! - `record`, `rig`, `fit`, `diagnose`, `sweep`: measured records, the virtual rig, the
//!   two-stage fit, the gap diagnosis, design sweeps.
//! - `work`: long work on a worker thread with the GIL released, progress and Ctrl-C.
//! - `errors`: library errors to the `stirling.errors` classes, with the library's messages.

#[cfg(feature = "python")]
mod arrays;
#[cfg(feature = "python")]
mod blocks;
#[cfg(feature = "python")]
mod convert;
#[cfg(feature = "python")]
mod cycle;
#[cfg(feature = "python")]
mod diagnose;
#[cfg(feature = "python")]
mod errors;
#[cfg(feature = "python")]
mod fit;
#[cfg(feature = "python")]
mod linear;
#[cfg(feature = "python")]
mod model;
#[cfg(feature = "python")]
mod params;
#[cfg(feature = "python")]
mod record;
#[cfg(feature = "python")]
mod rig;
#[cfg(feature = "python")]
mod simulate;
#[cfg(feature = "python")]
mod sweep;
#[cfg(feature = "python")]
mod work;

#[cfg(feature = "python")]
use pyo3::prelude::*;

/// The native module: its classes and functions (see `python/stirling/_native.pyi`).
#[cfg(feature = "python")]
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<model::NativeModel>()?;
    m.add_class::<record::NativeRecord>()?;
    m.add_function(wrap_pyfunction!(model::models, m)?)?;
    m.add_function(wrap_pyfunction!(linear::equilibrium, m)?)?;
    m.add_function(wrap_pyfunction!(linear::poles, m)?)?;
    m.add_function(wrap_pyfunction!(linear::linearize, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::initial_state, m)?)?;
    m.add_function(wrap_pyfunction!(cycle::limit_cycle, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(record::read_csv, m)?)?;
    m.add_function(wrap_pyfunction!(rig::rig, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::effects, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
