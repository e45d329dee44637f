//! A run of the model (BDF on the analytic Jacobian, the nonphysical-state check after every
//! step), exactly as `stirling simulate` runs it: the same samples, tolerances and checks, so
//! the arrays equal the command line's.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_dsl::{Model, StateKind};
use stirling_models::sim::{self, SimOptions, SimSummary, Trajectory};

use crate::arrays::{array1, array2};
use crate::convert::to_py;
use crate::errors::{Failure, Res};
use crate::model::NativeModel;
use crate::work;

/// The displacer displaced by `perturb` (m) from the closed-form rest state (the command
/// line's start without `--x0`).
pub fn start(model: &dyn Model, p: &[f64], perturb: f64) -> Res<Vec<f64>> {
    if !perturb.is_finite() {
        return Err(Failure::option(format!(
            "perturb = {perturb} is not a finite displacement (m)"
        )));
    }
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let ix = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(0))
        .ok_or_else(|| {
            Failure::option(format!(
                "`{}` has no displacer position to perturb: give x0",
                model.name()
            ))
        })?;
    x[ix] += perturb;
    Ok(x)
}

/// Tolerances and sample count, checked as the command line checks them.
pub struct RunOptions {
    pub t_end: f64,
    pub samples: usize,
    pub rtol: f64,
    pub atol: f64,
}

impl RunOptions {
    pub fn check(&self, what_t: &str) -> Res<()> {
        if !(self.t_end.is_finite() && self.t_end > 0.0) {
            return Err(Failure::option(format!(
                "{what_t} = {} must be a positive number of seconds",
                self.t_end
            )));
        }
        if !(2..=1_000_000).contains(&self.samples) {
            return Err(Failure::option(format!(
                "samples = {} must be from 2 to 1000000",
                self.samples
            )));
        }
        for (name, v) in [("rtol", self.rtol), ("atol", self.atol)] {
            if !(v > 0.0 && v <= 0.1) {
                return Err(Failure::option(format!("{name} = {v} must be in (0, 0.1]")));
            }
        }
        Ok(())
    }

    /// The sample times (the first at 0, the last at `t_end`) and the solver options.
    pub fn solver(&self) -> (Vec<f64>, SimOptions) {
        let opts = SimOptions {
            rtol: self.rtol,
            atol: self.atol,
            ..Default::default()
        };
        (sim::uniform_samples(self.t_end, self.samples - 1), opts)
    }
}

/// `t` and `x` of a run as arrays, with the solver counters.
pub fn trajectory<'py>(
    py: Python<'py>,
    tr: &Trajectory,
    n_states: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t", array1(py, tr.t.clone()))?;
    d.set_item("x", array2(py, &tr.x, n_states))?;
    d.set_item("stats", to_py(py, &tr.stats)?)?;
    Ok(d)
}

/// Simulate from `x0` over `[0, t_end]` (s), `samples` rows; `progress(t, t_end, None)`.
#[pyfunction]
#[pyo3(signature = (model, p, x0, t_end, samples, rtol, atol, progress=None))]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    x0: &Bound<'py, PyAny>,
    t_end: f64,
    samples: usize,
    rtol: f64,
    atol: f64,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (p, x0) = (model.params_of(p)?, model.state_of(x0, "x0")?);
    let run = RunOptions {
        t_end,
        samples,
        rtol,
        atol,
    };
    run.check("t_end")?;
    let m = model.dyn_model();
    let (times, opts) = run.solver();
    let tr = work::run(py, progress, t_end, |rep| {
        let checker = sim::PhysicalCheck::new(m, &p);
        let check = |t: f64, x: &[f64]| checker.check(t, x);
        let mut report = |t: f64| rep.at(t);
        let hooks = sim::Hooks {
            check: Some(&check),
            progress: Some(&mut report),
            ..Default::default()
        };
        sim::integrate(
            &sim::ModelSystem { model: m, p: &p },
            &x0,
            t_end,
            &times,
            &opts,
            hooks,
        )
    })?;
    let d = trajectory(py, &tr, m.n_states())?;
    d.set_item("summary", to_py(py, &SimSummary::from_run(m, &tr))?)?;
    Ok(d)
}

/// The closed-form rest state with the displacer displaced by `perturb` (m).
#[pyfunction]
pub fn initial_state<'py>(
    py: Python<'py>,
    model: &NativeModel,
    p: &Bound<'py, PyAny>,
    perturb: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let p = model.params_of(p)?;
    Ok(array1(py, start(model.dyn_model(), &p, perturb)?).into_any())
}
