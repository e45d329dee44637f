//! Limit cycles by single shooting.
//!
//! Poincare section: the piston position `y = 0` (the phase condition fixes
//! `y(0) = 0`; cycles start at an upward crossing, piston moving toward the
//! displacer). Unknowns `(x0, T)`, equations
//!
//! ```text
//! phi(x0, T) - x0 = 0          (n equations, return map)
//! y0 = 0                       (phase condition)
//! sum m_i(x0) = m_total        (inventory, `full` closure only)
//! ```
//!
//! solved by Gauss-Newton (least squares through an SVD, scaled by the state
//! magnitudes) with the monodromy matrix `Phi(T) = d phi / d x0` from the
//! variational equations `Phi' = J(x) Phi` built on the analytic Jacobian.
//! The Floquet multipliers are the eigenvalues of `Phi(T)`: one is 1 (the flow
//! direction), and with the `full` closure a second one is 1 (the conserved
//! inventory); the cycle is orbitally stable when all others lie inside the unit circle.
//!
//! The monodromy comes by default from [`crate::sim::monodromy`]: one BDF run of the state and a
//! 3-stage Radau IIA propagation of `Phi` along its steps (one LU of a `3n x 3n` stage matrix per
//! step for all columns, sparse for large `n`).
//! [`MonodromyMethod::Variational`](crate::sim::shooting::MonodromyMethod::Variational) keeps the
//! reference route: the `n (n + 1)`-state variational system under the adaptive BDF (dense
//! iteration matrix; a few dozen states at most).

use nalgebra::{DMatrix, DVector};
use stirling_dsl::{Model, StateKind};

use super::integrate::{integrate, Hooks, SimOptions, SolverStats};
use super::monodromy::flow_with_monodromy_radau;
use super::system::{state_scale, ModelSystem, VariationalSystem};
use super::SimError;

/// Newton settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShootingOptions {
    /// Converged when the scaled return-map residual is below this.
    pub tol: f64,
    /// Most Newton iterations.
    pub max_iter: usize,
    /// Integrator tolerances for the variational runs.
    pub sim: SimOptions,
    /// How the monodromy matrix is computed.
    pub monodromy: MonodromyMethod,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self {
            tol: 1e-7,
            max_iter: 12,
            sim: SimOptions {
                rtol: 1e-10,
                atol: 1e-10,
                ..SimOptions::default()
            },
            monodromy: MonodromyMethod::default(),
        }
    }
}

/// The monodromy route.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MonodromyMethod {
    /// State by the adaptive BDF; `Phi` by 3-stage Radau IIA along its steps,
    /// each step split into `substeps` equal parts.
    Radau { substeps: usize },
    /// The `n (n + 1)`-state variational system under the adaptive BDF (reference).
    Variational,
}

impl Default for MonodromyMethod {
    fn default() -> Self {
        MonodromyMethod::Radau { substeps: 1 }
    }
}

/// A converged periodic orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitCycle {
    /// State on the section (`y = 0`, upward).
    pub x0: Vec<f64>,
    /// Period (s).
    pub period: f64,
    /// Monodromy matrix (column-major, `n x n`).
    pub monodromy: Vec<f64>,
    /// Floquet multipliers `(re, im)`, largest modulus first.
    pub floquet: Vec<(f64, f64)>,
    /// Newton iterations used.
    pub iterations: usize,
    /// Final scaled residual.
    pub residual: f64,
    pub stats: SolverStats,
}

impl LimitCycle {
    /// Distance of the multiplier nearest to 1 from 1 (the trivial multiplier).
    pub fn trivial_multiplier_error(&self) -> f64 {
        self.floquet
            .iter()
            .map(|&(re, im)| ((re - 1.0).powi(2) + im * im).sqrt())
            .fold(f64::MAX, f64::min)
    }
}

/// The flow `phi(x0, T)` and its monodromy matrix by `method`.
pub fn flow_with_monodromy_by(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
    method: MonodromyMethod,
) -> Result<(Vec<f64>, Vec<f64>, SolverStats), SimError> {
    match method {
        MonodromyMethod::Radau { substeps } => {
            flow_with_monodromy_radau(model, p, x0, period, opts, substeps)
        }
        MonodromyMethod::Variational => flow_with_monodromy_variational(model, p, x0, period, opts),
    }
}

/// The flow `phi(x0, T)` and its monodromy matrix (the default route).
pub fn flow_with_monodromy(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
) -> Result<(Vec<f64>, Vec<f64>, SolverStats), SimError> {
    flow_with_monodromy_by(model, p, x0, period, opts, MonodromyMethod::default())
}

/// The flow `phi(x0, T)` and its monodromy matrix from the variational system.
pub fn flow_with_monodromy_variational(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
) -> Result<(Vec<f64>, Vec<f64>, SolverStats), SimError> {
    let n = model.n_states();
    let sys = VariationalSystem {
        inner: ModelSystem { model, p },
    };
    let mut z0 = x0.to_vec();
    for k in 0..n {
        for r in 0..n {
            z0.push(if r == k { 1.0 } else { 0.0 });
        }
    }
    let checker = super::physical::PhysicalCheck::new(model, p);
    let check = |t: f64, z: &[f64]| checker.check(t, &z[..n]);
    let hooks = Hooks {
        check: Some(&check),
        ..Default::default()
    };
    let tr = integrate(&sys, &z0, period, &[period], opts, hooks)?;
    let z = tr.x.last().cloned().unwrap_or(tr.x_end);
    Ok((z[..n].to_vec(), z[n..].to_vec(), tr.stats))
}

/// What closes the shooting system besides the return map: the Poincare section (the
/// piston position `iy` at zero) and, with mass states, the conserved inventory `m_total`.
pub(super) struct Section {
    /// State scales.
    pub(super) s: Vec<f64>,
    pub(super) iy: usize,
    pub(super) masses: Vec<usize>,
    pub(super) m_total: f64,
}

impl Section {
    /// The section of `model` at `p`, with the inventory of the start `x0`.
    pub(super) fn of(model: &dyn Model, p: &[f64], x0: &[f64]) -> Result<Section, SimError> {
        let masses = crate::layout::StateLayout::of(model).masses;
        let m_total: f64 = masses.iter().map(|&i| x0[i]).sum();
        Ok(Section {
            s: state_scale(model, p),
            iy: section_state(model)?,
            masses,
            m_total,
        })
    }

    /// The scaled Newton system for `(dx, dT/T)` at `x`, period `t_per`: monodromy `mono`,
    /// the field `f` at the return point, the scaled return residual `r`; the section row
    /// and the inventory row appended.
    fn newton_system(
        &self,
        mono: &[f64],
        f: &[f64],
        r: &[f64],
        x: &[f64],
        t_per: f64,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let (s, iy, masses, m_total) = (&self.s, self.iy, &self.masses, self.m_total);
        let n = x.len();
        let rows = n + 1 + usize::from(!masses.is_empty());
        let mut a = DMatrix::<f64>::zeros(rows, n + 1);
        let mut b = DVector::<f64>::zeros(rows);
        for i in 0..n {
            for j in 0..n {
                a[(i, j)] = (mono[i + j * n] - if i == j { 1.0 } else { 0.0 }) * s[j] / s[i];
            }
            a[(i, n)] = f[i] / s[i] * t_per;
            b[i] = -r[i];
        }
        a[(n, iy)] = 1.0;
        b[n] = -x[iy] / s[iy];
        if !masses.is_empty() {
            for &j in masses {
                a[(n + 1, j)] = s[j] / m_total;
            }
            b[n + 1] = -(masses.iter().map(|&j| x[j]).sum::<f64>() - m_total) / m_total;
        }
        (a, b)
    }
}

/// The state whose zero is the Poincare section: the second body's (the piston's) position.
fn section_state(model: &dyn Model) -> Result<usize, SimError> {
    let kinds = model.states();
    kinds
        .iter()
        .position(|s| s.kind == StateKind::Position(1))
        .ok_or_else(|| {
            SimError::BadOption(
                "shooting needs a second body (the power piston) for its section".into(),
            )
        })
}

/// Refine a periodic-orbit guess `(x0, period)` by Newton on the return map.
pub fn shoot(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &ShootingOptions,
) -> Result<LimitCycle, SimError> {
    let n = model.n_states();
    let sec = Section::of(model, p, x0)?;
    let s = &sec.s;
    let (mut x, mut t_per) = (x0.to_vec(), period);
    let mut stats = SolverStats::default();
    let mut f = vec![0.0; n];
    for it in 1..=opts.max_iter {
        let (phi, mono, st) =
            flow_with_monodromy_by(model, p, &x, t_per, &opts.sim, opts.monodromy)?;
        stats.add(&st);
        let r: Vec<f64> = (0..n).map(|i| (phi[i] - x[i]) / s[i]).collect();
        let res = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if res < opts.tol {
            return Ok(finish(x, t_per, mono, it, res, stats, n, s));
        }
        model.rhs(p, &phi, t_per, &mut f);
        let (a, b) = sec.newton_system(&mono, &f, &r, &x, t_per);
        let dz = a
            .svd(true, true)
            .solve(&b, 1e-12)
            .map_err(|e| SimError::ShootingFailed {
                iterations: it,
                residual: res,
                why: e.to_string(),
            })?;
        for j in 0..n {
            x[j] += dz[j] * s[j];
        }
        t_per *= 1.0 + dz[n];
        if !(t_per > 0.0) {
            return Err(SimError::ShootingFailed {
                iterations: it,
                residual: res,
                why: "the period became non-positive".into(),
            });
        }
    }
    let (phi, _, _) = flow_with_monodromy_by(model, p, &x, t_per, &opts.sim, opts.monodromy)?;
    let res = (0..n)
        .map(|i| ((phi[i] - x[i]) / s[i]).abs())
        .fold(0.0, f64::max);
    Err(SimError::ShootingFailed {
        iterations: opts.max_iter,
        residual: res,
        why: "Newton did not converge".into(),
    })
}

fn finish(
    x: Vec<f64>,
    period: f64,
    mono: Vec<f64>,
    iterations: usize,
    residual: f64,
    stats: SolverStats,
    n: usize,
    scale: &[f64],
) -> LimitCycle {
    LimitCycle {
        floquet: floquet_multipliers_scaled(&mono, n, scale),
        x0: x,
        period,
        monodromy: mono,
        iterations,
        residual,
        stats,
    }
}

/// Eigenvalues of `D^-1 Phi D` (`D = diag(scale)`, the same spectrum as `Phi`),
/// largest modulus first. The states span ten orders of magnitude (positions in
/// metres, pressures in pascal, masses in kilograms); without the similarity
/// scaling the eigen-solver's backward error, amplified by the double multiplier
/// 1 (a Jordan block: the period depends on the inventory), splits that pair by
/// `~sqrt(eps |Phi|)`.
pub fn floquet_multipliers_scaled(mono: &[f64], n: usize, scale: &[f64]) -> Vec<(f64, f64)> {
    let mut m = mono.to_vec();
    for j in 0..n {
        for i in 0..n {
            m[i + j * n] *= scale[j] / scale[i];
        }
    }
    floquet_multipliers(&m, n)
}

/// Eigenvalues of a column-major `n x n` monodromy matrix, largest modulus first.
pub fn floquet_multipliers(mono: &[f64], n: usize) -> Vec<(f64, f64)> {
    let m = DMatrix::from_column_slice(n, n, mono);
    let mut ev: Vec<(f64, f64)> = m
        .complex_eigenvalues()
        .iter()
        .map(|c| (c.re, c.im))
        .collect();
    ev.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
    ev
}
