//! The monodromy matrix without the `n (n + 1)`-state variational system.
//!
//! The state is integrated once by the adaptive BDF (same tolerances as a plain
//! run). After every accepted step `[t0, t1]` the variational equation
//! `Phi' = J(x(t)) Phi` is advanced over that step (split into `substeps` equal
//! parts) by the 3-stage Radau IIA method (order 5, L-stable, stiffly accurate),
//! with `x` at the stage times from the BDF's dense output:
//!
//! ```text
//! Z_i - h sum_j a_ij J(t0 + c_j h) Z_j = Phi(t0)   (i = 1..3),   Phi(t0 + h) = Z_3
//! ```
//!
//! One LU of the `3n x 3n` stage matrix per (sub)step serves all `n` columns of `Phi` (propagated
//! in state-scaled form `D^-1 Phi D`): nalgebra dense LU for small `n`, the refactoring sparse LU
//! ([`crate::sim::refactor_lu`]: column order once, on the union of the block patterns; pivots kept
//! from step to step) above [`crate::sim::SPARSE_THRESHOLD`] states (or as
//! [`SimOptions::linear_solver`] says). L-stability makes the stiff (pressure-equalization) modes
//! decay to ~0 as they should; the stage matrix is a rational function of `h J`, so a left null
//! vector of `J` (the mass inventory, `c J = 0`) stays a left eigenvector of the discrete `Phi`
//! with multiplier 1 exactly.
//!
//! Cost per step: `O(n^3)` dense, `O(nnz(LU) n)` sparse, against the old
//! `n (n + 1)` BDF states with an `n^2 x n^2` dense iteration matrix.

use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use nalgebra::DMatrix;
use stirling_dsl::Model;

use super::integrate::{integrate, Hooks, SimOptions, SolverStats};
use super::refactor_lu::RefactorLu;
use super::stage_slots::StageSlots;
use super::system::{state_scale, ModelSystem, OdeSystem};
use super::SimError;

/// Radau IIA, 3 stages: nodes and coefficients.
pub(super) fn radau3() -> ([f64; 3], [[f64; 3]; 3]) {
    let s6 = 6f64.sqrt();
    let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
    let a = [
        [
            (88.0 - 7.0 * s6) / 360.0,
            (296.0 - 169.0 * s6) / 1800.0,
            (-2.0 + 3.0 * s6) / 225.0,
        ],
        [
            (296.0 + 169.0 * s6) / 1800.0,
            (88.0 + 7.0 * s6) / 360.0,
            (-2.0 - 3.0 * s6) / 225.0,
        ],
        [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
    ];
    (c, a)
}

/// Sparse stage-matrix storage: the matrix on its pattern and its refactoring LU, reused
/// every step.
pub(super) struct SparseStage {
    mat: SparseColMat<usize, f64>,
    pub(super) lu: RefactorLu,
    /// A right-hand side of the stage system (`3 n`).
    pub(super) rhs: Vec<f64>,
    /// The solve's work vector (`3 n`).
    pub(super) work: Vec<f64>,
    /// Right-hand sides and work of the many-column solve (the dense monodromy's columns).
    many: Vec<f64>,
    many_work: Vec<f64>,
    /// Where the Jacobian triplets land in `mat`.
    slots: StageSlots,
}

impl SparseStage {
    pub(super) fn new(n: usize, pattern: &[(usize, usize)]) -> Result<Self, SimError> {
        let mut idx = Vec::with_capacity(9 * pattern.len() + 3 * n);
        for bi in 0..3 {
            for bj in 0..3 {
                idx.extend(
                    pattern
                        .iter()
                        .map(|&(r, c)| Pair::new(bi * n + r, bj * n + c)),
                );
            }
            idx.extend((0..n).map(|k| Pair::new(bi * n + k, bi * n + k)));
        }
        let (sym, _) =
            SymbolicSparseColMat::try_new_from_indices(3 * n, 3 * n, &idx).map_err(|e| {
                SimError::SolverFailure {
                    t: 0.0,
                    why: format!("monodromy stage matrix: {e:?}"),
                }
            })?;
        let nnz = sym.row_idx().len();
        Ok(Self {
            lu: RefactorLu::new(sym.as_ref()),
            mat: SparseColMat::new(sym, vec![0.0; nnz]),
            rhs: vec![0.0; 3 * n],
            work: vec![0.0; 3 * n],
            many: Vec::new(),
            many_work: Vec::new(),
            slots: StageSlots::default(),
        })
    }
}

/// Advances `Phi` along the BDF steps.
struct Propagator<'m> {
    sys: ModelSystem<'m>,
    n: usize,
    substeps: usize,
    phi: Vec<f64>,
    sparse: Option<SparseStage>,
    trip: [Vec<(usize, usize, f64)>; 3],
    x: Vec<f64>,
    /// `Phi` is propagated as `D^-1 Phi D`, `D = diag(scale)`: unscaled, the stage
    /// matrix spans twenty orders of magnitude and the sparse LU loses the answer.
    scale: Vec<f64>,
    jac_calls: usize,
    lu: usize,
}

impl Propagator<'_> {
    fn step(&mut self, t0: f64, t1: f64, dense: &dyn Fn(f64, &mut [f64])) -> Result<(), SimError> {
        let m = self.substeps.max(1);
        for k in 0..m {
            let a = t0 + (t1 - t0) * k as f64 / m as f64;
            let b = if k + 1 == m {
                t1
            } else {
                t0 + (t1 - t0) * (k + 1) as f64 / m as f64
            };
            self.radau(a, b, dense)?;
        }
        Ok(())
    }

    /// One Radau IIA step of `Phi` from `t0` to `t1`.
    fn radau(&mut self, t0: f64, t1: f64, dense: &dyn Fn(f64, &mut [f64])) -> Result<(), SimError> {
        let h = t1 - t0;
        if !(h > 0.0) {
            return Ok(());
        }
        let (c, a) = radau3();
        self.stage_jacobians(t0, h, &c, dense)?;
        self.lu += 1;
        let fail = |e: StageError| SimError::SolverFailure {
            t: t0,
            why: format!("monodromy step: {e}"),
        };
        let stage = StageStep {
            n: self.n,
            h,
            a: &a,
            trip: &self.trip,
        };
        match self.sparse.as_mut() {
            Some(sp) => stage.solve_sparse(sp, &mut self.phi),
            None => stage.solve_dense(&mut self.phi),
        }
        .map_err(fail)
    }

    /// The scaled Jacobian triplets at the three stage times (state from the dense output).
    fn stage_jacobians(
        &mut self,
        t0: f64,
        h: f64,
        c: &[f64; 3],
        dense: &dyn Fn(f64, &mut [f64]),
    ) -> Result<(), SimError> {
        for j in 0..3 {
            let tj = t0 + c[j] * h;
            dense(tj, &mut self.x);
            if self.x.iter().any(|v| !v.is_finite()) {
                return Err(SimError::SolverFailure {
                    t: tj,
                    why: "no dense output for the monodromy stage".into(),
                });
            }
            scaled_triplets(&self.sys, tj, &self.x, &self.scale, &mut self.trip[j]);
            self.jac_calls += 1;
        }
        Ok(())
    }
}

/// The scaled Jacobian `D^-1 J D` at `(t, x)` as triplets in `out` (cleared first).
pub(super) fn scaled_triplets(
    sys: &ModelSystem<'_>,
    t: f64,
    x: &[f64],
    scale: &[f64],
    out: &mut Vec<(usize, usize, f64)>,
) {
    out.clear();
    sys.jac_triplets(t, x, out);
    for e in out.iter_mut() {
        e.2 *= scale[e.1] / scale[e.0];
    }
}

/// The stage system of one Radau step: `(I - h A (x) J_j) K = Phi` stacked three times.
pub(super) struct StageStep<'t> {
    pub(super) n: usize,
    pub(super) h: f64,
    pub(super) a: &'t [[f64; 3]; 3],
    pub(super) trip: &'t [Vec<(usize, usize, f64)>; 3],
}

/// Why one Radau stage solve failed (mapped to [`SimError::SolverFailure`] at the step's time).
#[derive(Debug, thiserror::Error)]
pub(super) enum StageError {
    #[error("singular stage matrix")]
    Singular,
}

impl From<super::refactor_lu::Singular> for StageError {
    fn from(_: super::refactor_lu::Singular) -> Self {
        StageError::Singular
    }
}

impl StageStep<'_> {
    /// Assemble the stage matrix into `sp` and factorize it into `sp.lu`.
    pub(super) fn factor_sparse(&self, sp: &mut SparseStage) -> Result<(), StageError> {
        let (sym, vals) = sp.mat.parts_mut();
        sp.slots.assemble(
            sym.col_ptr(),
            sym.row_idx(),
            vals,
            self.n,
            self.h,
            self.a,
            self.trip,
        );
        sp.lu.factor(sp.mat.as_ref())?;
        Ok(())
    }

    /// Solve with the sparse LU of `sp` for every column of `phi` at once; `phi` becomes the
    /// last stage.
    fn solve_sparse(&self, sp: &mut SparseStage, phi: &mut [f64]) -> Result<(), StageError> {
        self.factor_sparse(sp)?;
        let n = self.n;
        let mut rhs = std::mem::take(&mut sp.many);
        rhs.resize(3 * n * n, 0.0);
        for (col, block) in phi.chunks_exact(n).zip(rhs.chunks_exact_mut(3 * n)) {
            for i in 0..3 {
                block[i * n..(i + 1) * n].copy_from_slice(col);
            }
        }
        sp.lu.solve_columns(&mut rhs, n, &mut sp.many_work)?;
        for (col, block) in phi.chunks_exact_mut(n).zip(rhs.chunks_exact(3 * n)) {
            col.copy_from_slice(&block[2 * n..]);
        }
        sp.many = rhs;
        Ok(())
    }

    /// Solve with a dense LU; `phi` becomes the last stage.
    fn solve_dense(&self, phi: &mut [f64]) -> Result<(), StageError> {
        let (n, h, a) = (self.n, self.h, self.a);
        let mut mat = DMatrix::<f64>::identity(3 * n, 3 * n);
        for i in 0..3 {
            for j in 0..3 {
                for &(r, cc, v) in &self.trip[j] {
                    mat[(i * n + r, j * n + cc)] -= h * a[i][j] * v;
                }
            }
        }
        let mut rhs = DMatrix::<f64>::zeros(3 * n, n);
        for col in 0..n {
            for i in 0..3 {
                for r in 0..n {
                    rhs[(i * n + r, col)] = phi[r + col * n];
                }
            }
        }
        if !mat.lu().solve_mut(&mut rhs) {
            return Err(StageError::Singular);
        }
        for col in 0..n {
            for r in 0..n {
                phi[r + col * n] = rhs[(2 * n + r, col)];
            }
        }
        Ok(())
    }
}

/// Solve the stage system (by `solve`, on a `3 n` right-hand side) for each `n`-row column
/// of `phi`; `phi` becomes the last stage.
pub(super) fn solve_stages(
    n: usize,
    rhs: &mut [f64],
    phi: &mut [f64],
    mut solve: impl FnMut(&mut [f64]),
) {
    for col in phi.chunks_exact_mut(n) {
        for i in 0..3 {
            rhs[i * n..(i + 1) * n].copy_from_slice(col);
        }
        solve(rhs);
        col.copy_from_slice(&rhs[2 * n..]);
    }
}

/// The callback of [`Hooks::on_step`]: `(t_prev, t, dense)` after every accepted step.
pub(super) type OnStep<'a> =
    dyn FnMut(f64, f64, &dyn Fn(f64, &mut [f64])) -> Result<(), SimError> + 'a;

/// One BDF run of the state over `period` from `x0`, nonphysical states refused, `on_step`
/// called after every accepted step (the recording of the monodromy and tangent routes);
/// the end state and the solver counters.
pub(super) fn run_recorded(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
    on_step: &mut OnStep,
) -> Result<(Vec<f64>, SolverStats), SimError> {
    let sys = ModelSystem { model, p };
    let checker = super::physical::PhysicalCheck::new(model, p);
    let check = |t: f64, x: &[f64]| checker.check(t, x);
    let hooks = Hooks {
        check: Some(&check),
        on_step: Some(on_step),
        ..Default::default()
    };
    let tr = integrate(&sys, x0, period, &[period], opts, hooks)?;
    let x_end = tr.x.last().cloned().unwrap_or(tr.x_end);
    Ok((x_end, tr.stats))
}

/// The flow `phi(x0, T)` and its monodromy matrix (column-major `n x n`), with
/// `substeps` Radau IIA steps per accepted BDF step.
pub fn flow_with_monodromy_radau(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
    substeps: usize,
) -> Result<(Vec<f64>, Vec<f64>, SolverStats), SimError> {
    let n = model.n_states();
    let sparse = if opts.linear_solver.use_sparse(n, true) {
        Some(SparseStage::new(n, &model.sparsity(p))?)
    } else {
        None
    };
    let mut phi = vec![0.0; n * n];
    for k in 0..n {
        phi[k + k * n] = 1.0;
    }
    let mut prop = Propagator {
        sys: ModelSystem { model, p },
        n,
        substeps,
        phi,
        sparse,
        trip: Default::default(),
        x: vec![0.0; n],
        scale: state_scale(model, p),
        jac_calls: 0,
        lu: 0,
    };
    let mut on_step = |t0: f64, t1: f64, dense: &dyn Fn(f64, &mut [f64])| prop.step(t0, t1, dense);
    let (x_end, mut stats) = run_recorded(model, p, x0, period, opts, &mut on_step)?;
    stats.jacobian_calls += prop.jac_calls;
    stats.lu_factorizations += prop.lu;
    let mut phi = prop.phi;
    for c in 0..n {
        for r in 0..n {
            phi[r + c * n] *= prop.scale[r] / prop.scale[c];
        }
    }
    Ok((x_end, phi, stats))
}
