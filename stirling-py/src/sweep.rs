//! Design sweeps (`stirling sweep`): a grid over any parameters; per point the dominant pole
//! at rest, whether the engine runs, and its limit cycle (frequency, strokes, phase, work,
//! power). The points run on every core.

use std::sync::atomic::AtomicU64;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_models::sim::SimOptions;
use stirling_models::sweep::grid::{self, Axis, Tie};
use stirling_models::sweep::{self as library, SweepOptions};

use crate::arrays::finite;
use crate::convert::to_dict;
use crate::errors::Failure;
use crate::model::NativeModel;
use crate::work;

/// Sweep `axes` (`[(name, values)]`, the last varying fastest) from the parameters `p`;
/// `ties` (`[(follower, leader)]`) keep a follower's ratio to its leader (`Pb` follows a swept
/// `Pmean` unless `untie`); `settle` (s) bounds each limit cycle's settling (`None`: poles
/// only).
#[pyfunction]
#[pyo3(signature = (model, p, axes, ties=Vec::new(), untie=false, settle=Some(10.0), progress=None))]
pub fn sweep<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    axes: Vec<(String, Vec<f64>)>,
    ties: Vec<(String, String)>,
    untie: bool,
    settle: Option<f64>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model.dyn_model();
    let p = model.params_of(p)?;
    let mut axes_v = Vec::new();
    for (name, values) in axes {
        finite(&values, &format!("the values of `{name}`"))?;
        if values.is_empty() {
            return Err(Failure::option(format!("the axis `{name}` has no values")).into());
        }
        axes_v.push(Axis { name, values });
    }
    if let Some(s) = settle {
        if !(s.is_finite() && s > 0.0) {
            return Err(Failure::option(format!(
                "settle = {s} must be a positive number of seconds"
            ))
            .into());
        }
    }
    let mut ties: Vec<Tie> = ties
        .into_iter()
        .map(|(follower, leader)| Tie { follower, leader })
        .collect();
    if !untie {
        let has = |n: &str| m.param_index(n).is_some();
        let extra: Vec<Tie> = grid::default_ties(&axes_v, has)
            .into_iter()
            .filter(|t| !ties.iter().any(|u| u.follower == t.follower))
            .collect();
        ties.extend(extra);
    }
    let opts = SweepOptions {
        axes: axes_v,
        ties,
        settle,
        shard: None,
        sim: SimOptions::default(),
    };
    let total = grid::count(&opts.axes) as f64;
    let s = work::run(py, progress, total, |rep| {
        let done = AtomicU64::new(0);
        library::run(m, &p, &opts, &|| rep.tick(&done))
    })?;
    to_dict(py, &s)
}
