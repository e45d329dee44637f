//! The ODE systems the integrator runs: a model, a model with an energy-budget
//! quadrature state, and a model with its variational equations.
//!
//! Every system gives `x' = f(t, x)` and a dense column-major Jacobian used as
//! the Newton iteration matrix of the implicit solver.

use stirling_dsl::{JacSink, Model, StateKind};

/// A first-order system `x' = f(t, x)` with its (possibly approximate) Jacobian.
pub trait OdeSystem {
    /// Number of states.
    fn dim(&self) -> usize;
    /// `out = f(t, x)`.
    fn rhs(&self, t: f64, x: &[f64], out: &mut [f64]);
    /// Add `df/dx` to `jac` (column-major, `dim` rows, zeroed by the caller).
    fn jac(&self, t: f64, x: &[f64], jac: &mut [f64]);
    /// Typical magnitude of each state, used to scale absolute tolerances.
    fn scale(&self) -> Vec<f64>;
    /// Structural pattern of `df/dx` as `(row, col)` pairs, if known (`None`:
    /// treat as dense; the sparse linear algebra is then never chosen automatically).
    fn sparsity(&self) -> Option<Vec<(usize, usize)>> {
        None
    }
    /// Append `df/dx` as `(row, col, value)` triplets (entries at one position add up).
    /// The default goes through the dense [`OdeSystem::jac`].
    fn jac_triplets(&self, t: f64, x: &[f64], out: &mut Vec<(usize, usize, f64)>) {
        let n = self.dim();
        let mut j = vec![0.0; n * n];
        self.jac(t, x, &mut j);
        for c in 0..n {
            for r in 0..n {
                let v = j[r + c * n];
                if v != 0.0 {
                    out.push((r, c, v));
                }
            }
        }
    }
}

/// Typical magnitudes of a model's states at equilibrium (position 1 cm,
/// velocity 1 m/s, pressure and mass their equilibrium values).
pub fn state_scale(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut eq = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut eq);
    model
        .states()
        .iter()
        .zip(&eq)
        .map(|(s, &e)| match s.kind {
            StateKind::Position(_) => 1e-2,
            StateKind::Velocity(_) => 1.0,
            StateKind::Pressure(_) | StateKind::Mass(_) | StateKind::WallTemperature(_) => {
                e.abs().max(f64::MIN_POSITIVE)
            }
        })
        .collect()
}

/// A model at fixed parameters.
pub struct ModelSystem<'m> {
    pub model: &'m dyn Model,
    pub p: &'m [f64],
}

impl ModelSystem<'_> {
    /// `out = f(t, x)` and `df/dx` added to `jac` (as [`OdeSystem::jac`]) in one pass.
    pub fn rhs_and_jac(&self, t: f64, x: &[f64], out: &mut [f64], jac: &mut [f64]) {
        let nrows = self.dim();
        let sink = &mut JacSink::Dense { data: jac, nrows };
        self.model.rhs_and_jacobian(self.p, x, t, out, sink);
    }
}

impl OdeSystem for ModelSystem<'_> {
    fn dim(&self) -> usize {
        self.model.n_states()
    }
    fn rhs(&self, t: f64, x: &[f64], out: &mut [f64]) {
        self.model.rhs(self.p, x, t, out);
    }
    fn jac(&self, t: f64, x: &[f64], jac: &mut [f64]) {
        let n = self.dim();
        self.model.jacobian(
            self.p,
            x,
            t,
            &mut JacSink::Dense {
                data: jac,
                nrows: n,
            },
        );
    }
    fn scale(&self) -> Vec<f64> {
        state_scale(self.model, self.p)
    }
    fn sparsity(&self) -> Option<Vec<(usize, usize)>> {
        Some(self.model.sparsity(self.p))
    }
    fn jac_triplets(&self, t: f64, x: &[f64], out: &mut Vec<(usize, usize, f64)>) {
        self.model
            .jacobian(self.p, x, t, &mut JacSink::Triplets(out));
    }
}

/// A model plus one quadrature state `z' = heat + boundary + mechanical`
/// (docs/physics.md section 10), so `z(t)` must equal `E(t) - E(0)`.
///
/// The quadrature row of the iteration matrix is left zero: `z` never feeds back,
/// so Newton still converges; accuracy is set by the error control, not the matrix.
pub struct EnergySystem<'m> {
    pub inner: ModelSystem<'m>,
}

impl OdeSystem for EnergySystem<'_> {
    fn dim(&self) -> usize {
        self.inner.dim() + 1
    }
    fn rhs(&self, t: f64, x: &[f64], out: &mut [f64]) {
        let n = self.inner.dim();
        self.inner.rhs(t, &x[..n], &mut out[..n]);
        let w = self.inner.model.power(self.inner.p, &x[..n]);
        out[n] = w.heat + w.boundary + w.mechanical;
    }
    fn jac(&self, t: f64, x: &[f64], jac: &mut [f64]) {
        let n = self.inner.dim();
        let mut j = vec![0.0; n * n];
        self.inner.jac(t, &x[..n], &mut j);
        for c in 0..n {
            jac[c * (n + 1)..c * (n + 1) + n].copy_from_slice(&j[c * n..(c + 1) * n]);
        }
    }
    fn scale(&self) -> Vec<f64> {
        let mut s = self.inner.scale();
        let e = self.inner.model.energy(self.inner.p, &{
            let mut eq = vec![0.0; self.inner.dim()];
            self.inner.model.equilibrium_guess(self.inner.p, &mut eq);
            eq
        });
        s.push(e.abs().max(1.0));
        s
    }
    fn sparsity(&self) -> Option<Vec<(usize, usize)>> {
        self.inner.sparsity()
    }
    fn jac_triplets(&self, t: f64, x: &[f64], out: &mut Vec<(usize, usize, f64)>) {
        let n = self.inner.dim();
        self.inner.jac_triplets(t, &x[..n], out);
    }
}

/// A model and its variational equations `Phi' = J(x) Phi`, `Phi(0) = I`:
/// state `[x, vec(Phi)]` (column-major), so `Phi(T)` is the monodromy matrix.
///
/// The iteration matrix is block diagonal `diag(J, J, .., J)`; the second-derivative
/// coupling `d(J Phi)/dx` is left out (it only slows Newton, never biases the result).
pub struct VariationalSystem<'m> {
    pub inner: ModelSystem<'m>,
}

impl OdeSystem for VariationalSystem<'_> {
    fn dim(&self) -> usize {
        let n = self.inner.dim();
        n * (n + 1)
    }
    fn rhs(&self, t: f64, x: &[f64], out: &mut [f64]) {
        let n = self.inner.dim();
        let mut j = vec![0.0; n * n];
        self.inner.rhs_and_jac(t, &x[..n], &mut out[..n], &mut j);
        for k in 0..n {
            let phi = &x[n + k * n..n + (k + 1) * n];
            let o = &mut out[n + k * n..n + (k + 1) * n];
            o.fill(0.0);
            for c in 0..n {
                let v = phi[c];
                if v != 0.0 {
                    for r in 0..n {
                        o[r] += j[r + c * n] * v;
                    }
                }
            }
        }
    }
    fn jac(&self, t: f64, x: &[f64], jac: &mut [f64]) {
        let n = self.inner.dim();
        let d = self.dim();
        let mut j = vec![0.0; n * n];
        self.inner.jac(t, &x[..n], &mut j);
        for b in 0..=n {
            let off = b * n;
            for c in 0..n {
                for r in 0..n {
                    jac[(off + r) + (off + c) * d] += j[r + c * n];
                }
            }
        }
    }
    fn scale(&self) -> Vec<f64> {
        let s = self.inner.scale();
        let n = s.len();
        let mut out = s.clone();
        for k in 0..n {
            for r in 0..n {
                out.push(s[r] / s[k]);
            }
        }
        out
    }
}
