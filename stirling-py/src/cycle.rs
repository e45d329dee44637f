//! The limit cycle: settle from a perturbed state, refine by shooting, and measure it
//! (frequency, strokes, phase, pressure amplitudes, Floquet multipliers, the work of every
//! vessel per cycle and the indicated power), as `stirling simulate --limit-cycle`.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_models::sim::{self, Shooting, SimSummary};

use crate::arrays::{array1, array2, complex};
use crate::convert::to_py;
use crate::errors::{Failure, Res};
use crate::model::NativeModel;
use crate::simulate::{trajectory, RunOptions};
use crate::work;

fn shooting(s: &str) -> Res<Shooting> {
    match s {
        "auto" => Ok(Shooting::Auto),
        "dense" => Ok(Shooting::Dense),
        "krylov" => Ok(Shooting::Krylov),
        "block" => Ok(Shooting::Block),
        "none" => Ok(Shooting::Never),
        _ => Err(Failure::option(format!(
            "shooting = `{s}`: expected \"auto\", \"dense\", \"block\", \"krylov\" or \"none\""
        ))),
    }
}

/// The limit cycle from `x0`, settling for at most `t_max` (s) sampled at `samples` rows.
#[pyfunction]
#[pyo3(signature = (model, p, x0, t_max, samples, rtol, atol, shooting="auto", progress=None))]
pub fn limit_cycle<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    t_max: f64,
    samples: usize,
    rtol: f64,
    atol: f64,
    shooting: &str,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (p, x0) = (model.params_of(p)?, model.state_of(x0, "x0")?);
    let run = RunOptions {
        t_end: t_max,
        samples,
        rtol,
        atol,
    };
    run.check("t_max")?;
    let route = self::shooting(shooting)?;
    let m = model.dyn_model();
    let (times, opts) = run.solver();
    let lc = work::run(py, progress, t_max, |rep| {
        let mut report = |t: f64| rep.at(t);
        sim::limit_cycle_with(m, &p, &x0, t_max, &times, &opts, route, Some(&mut report))
    })?;
    let n = m.n_states();
    let d = PyDict::new(py);
    let summary = SimSummary::from_run(m, &lc.settled.trajectory).with_cycle(&lc);
    d.set_item("summary", to_py(py, &summary)?)?;
    d.set_item("settled", trajectory(py, &lc.settled.trajectory, n)?)?;
    d.set_item("x0", array1(py, lc.cycle.x0.clone()))?;
    d.set_item("period", lc.cycle.period)?;
    d.set_item("iterations", lc.cycle.iterations)?;
    d.set_item("residual", lc.cycle.residual)?;
    d.set_item("floquet", complex(py, lc.cycle.floquet.iter().copied()))?;
    d.set_item("orbit", array2(py, &lc.orbit, n))?;
    d.set_item(
        "orbit_t",
        array1(
            py,
            sim::uniform_samples(lc.cycle.period, lc.orbit.len().saturating_sub(1)),
        ),
    )?;
    d.set_item("vessels", lc.work.vessels.clone())?;
    d.set_item("work_per_vessel", array1(py, lc.work.per_vessel.clone()))?;
    d.set_item("work", lc.work.total)?;
    let loops = sim::work::pv_loops(m, &p, &lc.orbit);
    let (vol, pre): (Vec<Vec<f64>>, Vec<Vec<f64>>) =
        loops.iter().map(|l| l.iter().copied().unzip()).unzip();
    d.set_item("volume", array2(py, &vol, lc.orbit.len()))?;
    d.set_item("pressure", array2(py, &pre, lc.orbit.len()))?;
    d.set_item("route", to_py(py, &lc.route)?)?;
    Ok(d)
}
