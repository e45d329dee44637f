//! The step loop: adaptive BDF (diffsol, dense LU, analytic Jacobian) on any
//! [`OdeSystem`](crate::sim::OdeSystem), with output at requested sample times, upward zero
//! crossings of one state (refined on the dense output), nonphysical-state checks after every
//! accepted step, and solver failures mapped to [`SimError`].
//!
//! Governing equation: `x' = f(t, x)` with error control
//! `|err_i| <= rtol |x_i| + atol scale_i` (`scale_i` from [`OdeSystem::scale`]).
//!
//! Linear algebra ([`LinearSolverKind`](crate::sim::integrate::LinearSolverKind)): dense nalgebra
//! LU (`O(n^3)` per factorization) for small systems, faer sparse LU on the structural pattern of
//! [`OdeSystem::sparsity`] for systems of more than
//! [`SPARSE_THRESHOLD`](crate::sim::integrate::SPARSE_THRESHOLD) states (by default; `nsection` at
//! n = 1000, 2008 states, needs it).

use diffsol::{DiffsolError, NalgebraLU, OdeBuilder, OdeSolverMethod, OdeSolverStopReason};
use serde::Serialize;
use stirling_dsl::Model;

use super::adapter::{Backend, DenseM, Eqn, SparseM};
use super::block_lu::BlockLu;
use super::dense_output::{crossing_between, map_err, on_step};
use super::system::{ModelSystem, OdeSystem};
use super::SimError;

/// Tolerances and limits of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance relative to each state's typical magnitude.
    pub atol: f64,
    /// Smallest step before the run is declared collapsed (s). Far below any time scale of the
    /// slow motion on purpose: the pressures of neighbouring regenerator sections equalize on a
    /// time scale that falls as `1 / n^2` (about 1e-14 s at n = 1000, 1e-16 s at n = 10,000), and
    /// from a start where they differ (a state given by hand, a shooting update) the first steps
    /// must resolve that before the step can grow. With 1e-13 s such starts failed at n >= 1000.
    pub min_step: f64,
    /// Largest number of steps.
    pub max_steps: usize,
    /// Dense or sparse linear algebra (default: chosen by size).
    pub linear_solver: LinearSolverKind,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-7,
            atol: 1e-7,
            min_step: 1e-20,
            max_steps: 5_000_000,
            linear_solver: LinearSolverKind::Auto,
        }
    }
}

/// Above this many states (and when the system knows its Jacobian pattern),
/// [`LinearSolverKind::Auto`] picks the sparse LU.
pub const SPARSE_THRESHOLD: usize = 20;

/// The linear algebra of the implicit solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinearSolverKind {
    /// Sparse when the system has a pattern and more than [`SPARSE_THRESHOLD`] states.
    #[default]
    Auto,
    /// Dense nalgebra LU.
    Dense,
    /// The refactoring sparse LU (`refactor_lu`; a full pattern if the system has none).
    Sparse,
}

impl LinearSolverKind {
    /// Whether a system of `dim` states (with a known pattern or not) goes sparse.
    pub fn use_sparse(self, dim: usize, has_pattern: bool) -> bool {
        match self {
            LinearSolverKind::Auto => has_pattern && dim > SPARSE_THRESHOLD,
            LinearSolverKind::Dense => false,
            LinearSolverKind::Sparse => true,
        }
    }
}

/// Solver counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct SolverStats {
    pub steps: usize,
    pub rhs_calls: usize,
    pub jacobian_calls: usize,
    pub lu_factorizations: usize,
    pub error_test_failures: usize,
    pub newton_failures: usize,
    /// Newton iterations of the corrector, over every step (accepted or not).
    pub newton_iterations: usize,
}

impl SolverStats {
    /// Sum of two runs' counters.
    pub fn add(&mut self, o: &SolverStats) {
        self.steps += o.steps;
        self.rhs_calls += o.rhs_calls;
        self.jacobian_calls += o.jacobian_calls;
        self.lu_factorizations += o.lu_factorizations;
        self.error_test_failures += o.error_test_failures;
        self.newton_failures += o.newton_failures;
        self.newton_iterations += o.newton_iterations;
    }
}

/// An upward zero crossing of the watched state.
#[derive(Clone, Debug, PartialEq)]
pub struct Crossing {
    pub t: f64,
    pub x: Vec<f64>,
}

/// Sampled output of a run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Sample times.
    pub t: Vec<f64>,
    /// States at the sample times (one row per sample).
    pub x: Vec<Vec<f64>>,
    /// Upward zero crossings of the watched state, if any was watched.
    pub crossings: Vec<Crossing>,
    /// Time and state where the run ended.
    pub t_end: f64,
    pub x_end: Vec<f64>,
    pub stats: SolverStats,
}

/// What to do during a run besides sampling.
#[derive(Default)]
pub struct Hooks<'h> {
    /// Watch this state for upward zero crossings.
    pub crossing: Option<usize>,
    /// Called at each crossing (with all crossings so far); `true` stops the run there.
    pub on_crossing: Option<&'h mut dyn FnMut(&[Crossing]) -> bool>,
    /// Reject nonphysical states (called after every accepted step).
    pub check: Option<&'h dyn Fn(f64, &[f64]) -> Result<(), SimError>>,
    /// Called after every accepted step with the current time.
    pub progress: Option<&'h mut dyn FnMut(f64)>,
    /// Called after every accepted step with `(t_prev, t, dense)`: `dense(s, out)`
    /// writes the state at any `s` in `[t_prev, t]` (the solver's dense output).
    #[allow(clippy::type_complexity)]
    pub on_step:
        Option<&'h mut dyn FnMut(f64, f64, &dyn Fn(f64, &mut [f64])) -> Result<(), SimError>>,
}

/// Uniform sample times `0, dt, .., t_end` (`count + 1` points).
pub fn uniform_samples(t_end: f64, count: usize) -> Vec<f64> {
    (0..=count)
        .map(|k| t_end * k as f64 / count.max(1) as f64)
        .collect()
}

/// Simulate a model from `x0` to `t_end`, sampling at `samples`, rejecting nonphysical states.
pub fn simulate(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    t_end: f64,
    samples: &[f64],
    opts: &SimOptions,
) -> Result<Trajectory, SimError> {
    let checker = super::physical::PhysicalCheck::new(model, p);
    let check = |t: f64, x: &[f64]| checker.check(t, x);
    let hooks = Hooks {
        check: Some(&check),
        ..Default::default()
    };
    integrate(&ModelSystem { model, p }, x0, t_end, samples, opts, hooks)
}

/// Build the BDF solver on one backend and run the step loop.
macro_rules! run {
    ($m:ty, $ls:ty, $sys:expr, $x0:expr, $t_end:expr, $samples:expr, $opts:expr, $atol:expr, $hooks:expr) => {{
        let eqn = Eqn::<$m>::new($sys, $x0.to_vec());
        let mut problem = OdeBuilder::<$m>::new()
            .rtol($opts.rtol)
            .atol($atol)
            .build_from_eqn(eqn)
            .map_err(|e| SimError::SolverFailure {
                t: 0.0,
                why: e.to_string(),
            })?;
        problem.ode_options.min_timestep = $opts.min_step;
        // diffsol counts Newton failures over the whole run, not per step: with the sharp
        // upwind switch of the enthalpy flows they add up on long runs. Step-size collapse
        // (min_step) is the real stop.
        problem.ode_options.max_nonlinear_solver_failures = $opts.max_steps;
        let mut solver = problem.bdf::<$ls>().map_err(|e| map_err(e, 0.0))?;
        solver.set_stop_time($t_end).map_err(|e| map_err(e, 0.0))?;
        step_loop::<$m, _>(&mut solver, $x0, $t_end, $samples, $opts, $hooks)
    }};
}

/// Integrate any system from `x0` at `t = 0` to `t_end`.
pub fn integrate(
    sys: &dyn OdeSystem,
    x0: &[f64],
    t_end: f64,
    samples: &[f64],
    opts: &SimOptions,
    hooks: Hooks,
) -> Result<Trajectory, SimError> {
    if x0.len() != sys.dim() {
        return Err(SimError::DimensionMismatch {
            expected: sys.dim(),
            found: x0.len(),
        });
    }
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(SimError::BadOption(format!(
            "the end time must be positive and finite, found {t_end}"
        )));
    }
    if let Some(check) = hooks.check {
        check(0.0, x0)?;
    }
    let atol: Vec<f64> = sys.scale().iter().map(|s| opts.atol * s).collect();
    if opts
        .linear_solver
        .use_sparse(sys.dim(), sys.sparsity().is_some())
    {
        run!(SparseM, BlockLu, sys, x0, t_end, samples, opts, atol, hooks)
    } else {
        run!(
            DenseM,
            NalgebraLU<f64>,
            sys,
            x0,
            t_end,
            samples,
            opts,
            atol,
            hooks
        )
    }
}

fn step_loop<'a, 's: 'a, M: Backend, S: OdeSolverMethod<'a, Eqn<'s, M>>>(
    solver: &mut S,
    x0: &[f64],
    t_end: f64,
    samples: &[f64],
    opts: &SimOptions,
    mut hooks: Hooks,
) -> Result<Trajectory, SimError> {
    let (mut out, mut next) = start_samples(samples, x0);
    let (mut t_prev, mut x_prev) = (0.0, x0.to_vec());
    let mut stopped = false;
    let interp = |y: Result<M::V, DiffsolError>, t: f64| -> Result<Vec<f64>, SimError> {
        y.map(|v| M::slice(&v).to_vec()).map_err(|e| map_err(e, t))
    };
    for _ in 0..opts.max_steps {
        let reason = solver.step().map_err(|e| map_err(e, solver.state().t))?;
        let t = solver.state().t;
        super::interrupt::check(t)?;
        let x = M::slice(solver.state().y).to_vec();
        if let Some(check) = hooks.check {
            check(t, &x)?;
        }
        while next < samples.len() && samples[next] <= t {
            out.t.push(samples[next]);
            out.x.push(interp(solver.interpolate(samples[next]), t)?);
            next += 1;
        }
        if let Some(k) = hooks.crossing {
            let c = crossing_between::<M, S>(solver, k, (t_prev, x_prev[k]), (t, x[k]))?;
            if let Some(c) = c {
                out.crossings.push(c);
                if let Some(f) = hooks.on_crossing.as_mut() {
                    if f(&out.crossings) {
                        stopped = true;
                    }
                }
            }
        }
        if let Some(f) = hooks.on_step.as_mut() {
            on_step::<M, S>(solver, &mut **f, t_prev, t)?;
        }
        if let Some(f) = hooks.progress.as_mut() {
            f(t);
        }
        (t_prev, x_prev) = (t, x);
        if stopped || reason == OdeSolverStopReason::TstopReached {
            break;
        }
    }
    if !stopped && t_prev < t_end {
        return Err(SimError::TooManySteps {
            t: t_prev,
            max_steps: opts.max_steps,
        });
    }
    out.t_end = t_prev;
    out.x_end = x_prev;
    out.stats = solver_stats::<M, S>(solver);
    Ok(out)
}

/// A trajectory holding the samples at or before the start (all `x0`); the next sample index.
fn start_samples(samples: &[f64], x0: &[f64]) -> (Trajectory, usize) {
    let mut out = Trajectory::default();
    let mut next = 0;
    while next < samples.len() && samples[next] <= 0.0 {
        out.t.push(samples[next]);
        out.x.push(x0.to_vec());
        next += 1;
    }
    (out, next)
}

/// The solver's work counters.
fn solver_stats<'a, 's: 'a, M: Backend, S: OdeSolverMethod<'a, Eqn<'s, M>>>(
    solver: &S,
) -> SolverStats {
    let st = solver.get_statistics();
    SolverStats {
        steps: st.number_of_steps,
        rhs_calls: solver.problem().eqn.n_rhs.get(),
        jacobian_calls: solver.problem().eqn.n_jac.get(),
        lu_factorizations: st.number_of_linear_solver_setups,
        error_test_failures: st.number_of_error_test_failures,
        newton_failures: st.number_of_nonlinear_solver_fails,
        newton_iterations: st.number_of_nonlinear_solver_iterations,
    }
}

pub use super::physical::check_physical;
