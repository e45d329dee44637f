//! The step loop's use of the solver's dense output: upward zero crossings refined by
//! regula falsi, the per-step hook, and the mapping of solver errors to [`SimError`].

use diffsol::{error::OdeSolverError, DiffsolError, OdeSolverMethod};

use super::adapter::{Backend, Eqn};
use super::integrate::Crossing;
use super::SimError;

/// The upward zero crossing of state `k` in the last step `(t_prev, t]` (values `g_prev`,
/// `g`), refined on the dense output; `None` if it did not cross.
pub(super) fn crossing_between<'a, 's: 'a, M: Backend, S: OdeSolverMethod<'a, Eqn<'s, M>>>(
    solver: &S,
    k: usize,
    (t_prev, g_prev): (f64, f64),
    (t, g): (f64, f64),
) -> Result<Option<Crossing>, SimError> {
    if !(g_prev < 0.0 && g >= 0.0) {
        return Ok(None);
    }
    let tc = refine_crossing::<M, S>(solver, k, (t_prev, g_prev), (t, g));
    let x = solver
        .interpolate(tc)
        .map(|v| M::slice(&v).to_vec())
        .map_err(|e| map_err(e, t))?;
    Ok(Some(Crossing { t: tc, x }))
}

/// Call the step hook `f` with the dense output over the last step `[t_prev, t]`.
pub(super) fn on_step<'a, 's: 'a, M: Backend, S: OdeSolverMethod<'a, Eqn<'s, M>>>(
    solver: &S,
    f: &mut dyn FnMut(f64, f64, &dyn Fn(f64, &mut [f64])) -> Result<(), SimError>,
    t_prev: f64,
    t: f64,
) -> Result<(), SimError> {
    let dense = |tau: f64, y: &mut [f64]| match solver.interpolate(tau) {
        Ok(v) => y.copy_from_slice(M::slice(&v)),
        Err(_) => y.fill(f64::NAN),
    };
    f(t_prev, t, &dense)
}

/// Illinois regula falsi on the dense output for the zero of state `k` in `(a, b)`.
fn refine_crossing<'a, 's: 'a, M: Backend, S: OdeSolverMethod<'a, Eqn<'s, M>>>(
    solver: &S,
    k: usize,
    a: (f64, f64),
    b: (f64, f64),
) -> f64 {
    let (mut ta, mut ga) = a;
    let (mut tb, mut gb) = b;
    let mut side = 0;
    for _ in 0..60 {
        if gb == ga {
            break;
        }
        let tc = tb - gb * (tb - ta) / (gb - ga);
        let gc = match solver.interpolate(tc) {
            Ok(y) => M::slice(&y)[k],
            Err(_) => return tc,
        };
        if (tb - ta).abs() < 1e-15 * tb.abs().max(1.0) || gc == 0.0 {
            return tc;
        }
        if (gc < 0.0) == (ga < 0.0) {
            (ta, ga) = (tc, gc);
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            (tb, gb) = (tc, gc);
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
    }
    tb - gb * (tb - ta) / (gb - ga)
}

pub(super) fn map_err(e: DiffsolError, t: f64) -> SimError {
    match e {
        DiffsolError::OdeSolverError(OdeSolverError::StepSizeTooSmall { time }) => {
            SimError::StepSizeCollapse { t: time }
        }
        DiffsolError::OdeSolverError(OdeSolverError::TooManyNonlinearSolverFailures {
            time,
            num_failures,
        }) => SimError::SolverFailure {
            t: time,
            why: format!("Newton failed to converge ({num_failures} failures in the run)"),
        },
        DiffsolError::OdeSolverError(OdeSolverError::TooManyErrorTestFailures {
            time,
            num_failures,
        }) => SimError::SolverFailure {
            t: time,
            why: format!("{num_failures} consecutive error-test failures"),
        },
        other => SimError::SolverFailure {
            t,
            why: other.to_string(),
        },
    }
}
