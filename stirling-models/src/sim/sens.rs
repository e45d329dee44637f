//! Forward sensitivities by the staggered corrector (CVODES' "staggered direct"), through
//! diffsol's own sensitivity BDF: the states `x' = f(t, x)` are stepped by Newton on the
//! `n x n` matrix `I - c J`; after each converged state the sensitivity columns
//! `S' = J S + F(t, x)`, `S(0) = S0`, are corrected with the *same* factorization, all columns
//! at once (one lane each), `J` evaluated once at the new state and `F` once per step. The
//! error test covers the states and every column (`sens_rtol = rtol`, `sens_atol = atol`
//! scaled like the states), so the columns are as accurate as in the augmented system.
//!
//! Why not the augmented system `[x, S]` any more: there every Newton iteration of every step
//! evaluated the Jacobian and the parameter Jacobian (inside the augmented right-hand side),
//! formed the `(1 + k) n` Newton matrix and scattered it; on the `p, x, y` diagnosis that was
//! about half of the run. Here those costs fall to once per step and `n x n`.
//!
//! Dense storage only: the driven subsystems the fit integrates have a few states.

use diffsol::{
    ConstantOpSens, Matrix, NonLinearOpSens, OdeBuilder, OdeSolverMethod, OdeSolverStopReason,
};

use super::adapter::{Backend, DenseM, Eqn, Init, Rhs};
use super::dense_output::map_err;
use super::integrate::SimOptions;
use super::lane_lu::LaneLu;
use super::system::OdeSystem;
use super::SimError;

/// The sensitivity part of a system: `k` columns with `S' = J S + F(t, x)`, `S(0) = S0`.
pub trait SensSystem {
    /// Number of columns `k`.
    fn n_sens(&self) -> usize;
    /// `F(t, x)`, column-major `dim x k` (every entry written).
    fn sens_forcing(&self, t: f64, x: &[f64], out: &mut [f64]);
    /// `S0`, column-major `dim x k` (every entry written).
    fn sens_initial(&self, out: &mut [f64]);
}

/// `y = M v` for the column-major `n x k` matrix `m`.
fn mat_vec(m: &[f64], n: usize, v: &[f64], y: &mut [f64]) {
    y.fill(0.0);
    for (c, &vc) in v.iter().enumerate() {
        if vc != 0.0 {
            y.iter_mut()
                .zip(&m[c * n..(c + 1) * n])
                .for_each(|(a, b)| *a += b * vc);
        }
    }
}

impl NonLinearOpSens for Rhs<'_, '_, DenseM> {
    fn sens_mul_inplace(
        &self,
        x: &<DenseM as diffsol::MatrixCommon>::V,
        t: f64,
        v: &<DenseM as diffsol::MatrixCommon>::V,
        y: &mut <DenseM as diffsol::MatrixCommon>::V,
    ) {
        let Some(s) = self.0.sens else {
            DenseM::slice_mut(y).fill(0.0);
            return;
        };
        let n = self.0.y0.len();
        let mut f = vec![0.0; n * s.n_sens()];
        s.sens_forcing(t, DenseM::slice(x), &mut f);
        mat_vec(&f, n, DenseM::slice(v), DenseM::slice_mut(y));
    }

    fn sens_inplace(&self, x: &<DenseM as diffsol::MatrixCommon>::V, t: f64, y: &mut DenseM) {
        let data = y.inner_mut().as_mut_slice();
        match self.0.sens {
            Some(s) => s.sens_forcing(t, DenseM::slice(x), data),
            None => data.fill(0.0),
        }
    }
}

impl ConstantOpSens for Init<'_, '_, DenseM> {
    fn sens_mul_inplace(
        &self,
        _t: f64,
        v: &<DenseM as diffsol::MatrixCommon>::V,
        y: &mut <DenseM as diffsol::MatrixCommon>::V,
    ) {
        let Some(s) = self.0.sens else {
            DenseM::slice_mut(y).fill(0.0);
            return;
        };
        let n = self.0.y0.len();
        let mut s0 = vec![0.0; n * s.n_sens()];
        s.sens_initial(&mut s0);
        mat_vec(&s0, n, DenseM::slice(v), DenseM::slice_mut(y));
    }

    fn sens_inplace(&self, _t: f64, y: &mut DenseM) {
        let data = y.inner_mut().as_mut_slice();
        match self.0.sens {
            Some(s) => s.sens_initial(data),
            None => data.fill(0.0),
        }
    }
}

/// Integrate `sys` with the sensitivities `sens` from `x0` at `t = 0` to `t_end`; one row per
/// sample time: `[x, S]` with `S` column-major (`x` then column 0, column 1, ...), the layout
/// of the augmented system.
pub fn integrate_sens(
    sys: &dyn OdeSystem,
    sens: &dyn SensSystem,
    x0: &[f64],
    t_end: f64,
    samples: &[f64],
    opts: &SimOptions,
) -> Result<Vec<Vec<f64>>, SimError> {
    let (n, k) = (sys.dim(), sens.n_sens());
    if x0.len() != n {
        return Err(SimError::DimensionMismatch {
            expected: n,
            found: x0.len(),
        });
    }
    if !(t_end > 0.0 && t_end.is_finite()) {
        return Err(SimError::BadOption(format!(
            "the end time must be positive and finite, found {t_end}"
        )));
    }
    let atol: Vec<f64> = sys.scale().iter().map(|s| opts.atol * s).collect();
    let eqn = Eqn::<DenseM>::with_sens(sys, sens, x0.to_vec());
    let mut problem = OdeBuilder::<DenseM>::new()
        .rtol(opts.rtol)
        .atol(atol.clone())
        .sens_rtol(opts.rtol)
        .sens_atol(atol)
        .p(vec![0.0; k])
        .build_from_eqn(eqn)
        .map_err(|e| map_err(e, 0.0))?;
    problem.ode_options.min_timestep = opts.min_step;
    // as in `integrate`: Newton failures are counted over the run; the step-size floor stops
    problem.ode_options.max_nonlinear_solver_failures = opts.max_steps;
    let mut solver = problem.bdf_sens::<LaneLu>().map_err(|e| map_err(e, 0.0))?;
    solver.set_stop_time(t_end).map_err(|e| map_err(e, 0.0))?;
    let mut rows = Vec::with_capacity(samples.len());
    let mut next = 0;
    if samples.first().is_some_and(|&s| s <= 0.0) {
        let mut s0 = vec![0.0; n * k];
        sens.sens_initial(&mut s0);
        let row: Vec<f64> = x0.iter().chain(&s0).copied().collect();
        while next < samples.len() && samples[next] <= 0.0 {
            rows.push(row.clone());
            next += 1;
        }
    }
    for _ in 0..opts.max_steps {
        let reason = solver.step().map_err(|e| map_err(e, solver.state().t))?;
        let t = solver.state().t;
        super::interrupt::check(t)?;
        while next < samples.len() && samples[next] <= t {
            let ts = samples[next];
            let x = solver.interpolate(ts).map_err(|e| map_err(e, t))?;
            let s = solver.interpolate_sens(ts).map_err(|e| map_err(e, t))?;
            let mut row = DenseM::slice(&x).to_vec();
            row.extend_from_slice(DenseM::slice(&s));
            rows.push(row);
            next += 1;
        }
        if reason == OdeSolverStopReason::TstopReached {
            return Ok(rows);
        }
    }
    Err(SimError::TooManySteps {
        t: solver.state().t,
        max_steps: opts.max_steps,
    })
}
