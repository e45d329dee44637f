//! The equilibrium `f(x*) = 0` by Newton's method with the analytic Jacobian.
//!
//! The iteration starts from [`Model::equilibrium_guess`] (docs/physics.md section 6, exact for the
//! family) and solves `J dx = -f`, halving the step while the scaled residual grows. With the
//! `full` closure the total gas mass is conserved (`c J = 0`, `c` = ones on the mass states),
//! so `J` is singular: the last mass equation is replaced by the inventory constraint
//! `c x = c x0` (the charge of the guess), which makes the system regular.
//!
//! Above [`SPARSE_FROM`](crate::linear::equilibrium::SPARSE_FROM) states the Newton system is
//! solved by a faer sparse LU of the Jacobian triplets (same matrix, same row replacement); below,
//! by the dense LU as before.
//!
//! Residuals are scaled per state: `r_i = |f_i| / s_i` with `s_i = max(|x0_i|, floor(kind))`,
//! i.e. the relative rate of change of each state, in 1/s.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use stirling_dsl::{Model, StateKind};

use super::LinearError;

/// The smallest state count whose Newton systems are solved by the sparse LU.
pub const SPARSE_FROM: usize = 401;

/// How the Newton system is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NewtonSolver {
    /// Dense below [`SPARSE_FROM`] states, sparse from there on.
    Auto,
    Dense,
    Sparse,
}

impl NewtonSolver {
    fn sparse(self, n: usize) -> bool {
        match self {
            Self::Auto => n >= SPARSE_FROM,
            Self::Dense => false,
            Self::Sparse => true,
        }
    }
}

/// Newton settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Converged when the scaled residual `max_i |f_i| / s_i` is below this (1/s).
    pub tol: f64,
    /// Iteration limit.
    pub max_iter: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tol: 1e-8,
            max_iter: 50,
        }
    }
}

/// A solved equilibrium.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Equilibrium {
    /// The state at rest.
    pub x: Vec<f64>,
    /// `max_i |f_i(x)|` (mixed units).
    pub residual: f64,
    /// `max_i |f_i(x)| / s_i` (1/s).
    pub scaled_residual: f64,
    /// Newton iterations taken (0: the guess already satisfied the tolerance).
    pub iterations: usize,
}

/// Typical magnitude of each state, for scaling residuals and steps.
pub fn state_scales(model: &dyn Model, x: &[f64]) -> Vec<f64> {
    model
        .states()
        .iter()
        .zip(x)
        .map(|(s, &v)| {
            let floor = match s.kind {
                StateKind::Position(_) => 1e-3,
                StateKind::Velocity(_) => 1e-1,
                StateKind::Pressure(_) => 1e3,
                StateKind::Mass(_) => 1e-9,
                StateKind::WallTemperature(_) => 1.0,
            };
            v.abs().max(floor)
        })
        .collect()
}

/// Indices of the mass states (empty unless the closure is `full`).
pub fn mass_states(model: &dyn Model) -> Vec<usize> {
    crate::layout::StateLayout::of(model).masses
}

/// Solve from the model's own guess.
pub fn solve(
    model: &dyn Model,
    p: &[f64],
    opts: &NewtonOptions,
) -> Result<Equilibrium, LinearError> {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    solve_from(model, p, &x0, opts)
}

fn scaled(f: &[f64], s: &[f64]) -> f64 {
    f.iter()
        .zip(s)
        .map(|(f, s)| (f / s).abs())
        .fold(0.0, f64::max)
}

fn eval(model: &dyn Model, p: &[f64], x: &[f64]) -> Result<Vec<f64>, LinearError> {
    let mut f = vec![0.0; x.len()];
    model.rhs(p, x, 0.0, &mut f);
    if f.iter().all(|v| v.is_finite()) {
        Ok(f)
    } else {
        Err(LinearError::NonFinite {
            what: "right-hand side",
        })
    }
}

/// Solve from a given start `x0`; with mass states its total charge is kept.
pub fn solve_from(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    opts: &NewtonOptions,
) -> Result<Equilibrium, LinearError> {
    solve_with(model, p, x0, opts, NewtonSolver::Auto)
}

/// [`solve_from`] with the linear solver chosen by the caller.
pub fn solve_with(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    opts: &NewtonOptions,
    solver: NewtonSolver,
) -> Result<Equilibrium, LinearError> {
    let sparse = solver.sparse(x0.len());
    let s = state_scales(model, x0);
    let masses = mass_states(model);
    let charge: f64 = masses.iter().map(|&i| x0[i]).sum();
    let mut x = x0.to_vec();
    let mut f = eval(model, p, &x)?;
    let mut r = scaled(&f, &s);
    let mut it = 0;
    while r > opts.tol {
        if it == opts.max_iter {
            return Err(LinearError::NoConvergence {
                iterations: it,
                residual: r,
                tol: opts.tol,
            });
        }
        it += 1;
        let dx = newton_step(model, p, &x, &f, (&masses, charge), sparse)
            .ok_or(LinearError::Singular { iteration: it })?;
        let (xn, fnew, rn) = line_search(model, p, &x, &dx, &s, r)?;
        x = xn;
        f = fnew;
        r = rn;
    }
    let residual = f.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    if let Err(crate::sim::SimError::Nonphysical {
        quantity, value, ..
    }) = crate::sim::physical::check_physical(model, p, 0.0, &x)
    {
        return Err(LinearError::Nonphysical { quantity, value });
    }
    Ok(Equilibrium {
        x,
        residual,
        scaled_residual: r,
        iterations: it,
    })
}

/// The Newton step `J dx = -f` with the last mass equation replaced by the inventory
/// constraint, by the dense LU or (with `sparse`) the sparse LU on the Jacobian triplets.
fn newton_step(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    f: &[f64],
    (masses, charge): (&[usize], f64),
    sparse: bool,
) -> Option<DVector<f64>> {
    let n = x.len();
    let mut rhs: Vec<f64> = f.iter().map(|v| -v).collect();
    let last = masses.last().copied();
    if let Some(last) = last {
        rhs[last] = charge - masses.iter().map(|&i| x[i]).sum::<f64>();
    }
    if sparse {
        // the same system as triplets, by the sparse LU
        let entries = model.jacobian_triplets(p, x, 0.0);
        let m = super::sparse::SparseMatrix { n, entries };
        let dx = match last {
            Some(last) => super::sparse::solve_constrained(&m, last, masses, &rhs),
            None => super::sparse::solve_real(&m, &rhs),
        }
        .ok()??;
        return Some(DVector::from_vec(dx));
    }
    let mut j = DMatrix::from_vec(n, n, model.jacobian_dense(p, x, 0.0));
    if let Some(last) = last {
        j.row_mut(last).fill(0.0);
        for &i in masses {
            j[(last, i)] = 1.0;
        }
    }
    super::solve::solve(&j, &DVector::from_vec(rhs))
}

type Trial = (Vec<f64>, Vec<f64>, f64);

fn line_search(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    dx: &DVector<f64>,
    s: &[f64],
    r: f64,
) -> Result<Trial, LinearError> {
    let mut lambda = 1.0;
    let mut best: Option<Trial> = None;
    for _ in 0..30 {
        let xn: Vec<f64> = x
            .iter()
            .zip(dx.iter())
            .map(|(a, d)| a + lambda * d)
            .collect();
        if let Ok(f) = eval(model, p, &xn) {
            let rn = scaled(&f, s);
            if rn < r {
                return Ok((xn, f, rn));
            }
            if !matches!(&best, Some(b) if b.2 <= rn) {
                best = Some((xn, f, rn));
            }
        }
        lambda *= 0.5;
    }
    best.ok_or(LinearError::NonFinite {
        what: "right-hand side along the Newton step",
    })
}
