//! Monodromy-vector products `Phi v` without the monodromy matrix: the directional (one-column)
//! form of [`crate::sim::monodromy`].
//!
//! [`flow_with_tangent`](crate::sim::tangent::flow_with_tangent) integrates the state once by the
//! adaptive BDF and records, for every accepted step (split into `substeps` equal parts), the step
//! `(t0, h)` and the state at the three Radau IIA stage times from the dense output.
//! [`TangentFlow::apply`](crate::sim::tangent::TangentFlow::apply) then advances one vector `v`
//! along the recorded steps by the same 3-stage Radau IIA stage system as the dense route,
//!
//! ```text
//! (I - h A (x) J_s(t0 + c_j h)) K = (v, v, v),   v <- K_3,
//! ```
//!
//! in state-scaled form (`J_s = D^-1 J D`), so a product is `D^-1 Phi D v` with the same discrete
//! `Phi` as [`crate::sim::monodromy::flow_with_monodromy_radau`] (to round-off: same steps, same
//! stage states, same stage matrices). The stage matrix is factored by the refactoring sparse LU
//! ([`crate::sim::refactor_lu`]: column order once, pivots kept from step to step); the factors'
//! values of the first steps are kept up to [`TangentFlow`](crate::sim::tangent::TangentFlow)'s
//! memory budget, so repeated products (GMRES, Arnoldi) cost one triangular solve per step there
//! and a refactorization (no pivot search) only past the budget.
//!
//! Why this route and not the staggered sensitivities of [`crate::sim::sens`]: those re-run the
//! corrector of the BDF for every direction (a full nonlinear run per product), while here a
//! product is linear work on stored data, and it reproduces the dense route's `Phi` exactly, which
//! the route-equality test relies on.

use stirling_dsl::Model;

use super::integrate::{SimOptions, SolverStats};
use super::monodromy::{
    radau3, run_recorded, scaled_triplets, solve_stages, SparseStage, StageStep,
};
use super::refactor_lu::LuSnapshot;
use super::system::{state_scale, ModelSystem};
use super::SimError;

/// The recorded orbit and the operator `v -> D^-1 Phi D v`.
pub struct TangentFlow<'m> {
    pub(super) sys: ModelSystem<'m>,
    pub(super) n: usize,
    /// `(t0, h)` of every Radau step.
    pub(super) steps: Vec<(f64, f64)>,
    /// The states at the three stage times, `3 n` per step.
    pub(super) stage_x: Vec<f64>,
    sparse: SparseStage,
    /// The Jacobian's structural pattern (the stage matrices' of the parallel sweep).
    pub(super) pattern: Vec<(usize, usize)>,
    /// The factors of the first steps' stage matrices.
    cache: Vec<LuSnapshot>,
    /// Bytes the cache may hold, and holds.
    cache_budget: usize,
    cache_used: usize,
    trip: [Vec<(usize, usize, f64)>; 3],
    pub(super) scale: Vec<f64>,
    /// Products applied so far.
    pub products: usize,
    /// Stage-matrix factorizations so far.
    pub factorizations: usize,
    /// Jacobian evaluations so far.
    pub jacobian_calls: usize,
}

impl TangentFlow<'_> {
    /// The number of states.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// The number of recorded Radau steps.
    pub fn steps(&self) -> usize {
        self.steps.len()
    }

    /// How many steps keep their stage factors.
    pub fn cached_steps(&self) -> usize {
        self.cache.len()
    }

    /// `v <- D^-1 Phi D v` (`v` of length `n`, state-scaled).
    pub fn apply(&mut self, v: &mut [f64]) -> Result<(), SimError> {
        if v.len() != self.n {
            return Err(SimError::DimensionMismatch {
                expected: self.n,
                found: v.len(),
            });
        }
        self.products += 1;
        for k in 0..self.steps.len() {
            if k >= self.cache.len() {
                self.factor(k)?;
            }
            let sp = &mut self.sparse;
            match self.cache.get(k) {
                Some(kept) => solve_stages(self.n, &mut sp.rhs, v, |r| kept.solve(r, &mut sp.work)),
                None => {
                    let lu = &sp.lu;
                    solve_stages(self.n, &mut sp.rhs, v, |r| {
                        lu.solve(r).expect("factored just above")
                    })
                }
            }
        }
        Ok(())
    }

    /// `V <- D^-1 Phi D V` for the `k` columns of `v` (column-major `n x k`): one sweep over
    /// the steps, each stage matrix factored once (or its kept factors used) for all columns.
    /// Without kept factors the stage matrices are factored on
    /// [`sweep_threads`](crate::sim::tangent_sweep::sweep_threads) threads.
    pub fn apply_block(&mut self, v: &mut [f64], k: usize) -> Result<(), SimError> {
        self.apply_block_threads(v, k, super::tangent_sweep::sweep_threads())
    }

    /// [`TangentFlow::apply_block`] with `threads` factoring threads (1: all on this one). The
    /// products agree to round-off whatever the count (each thread keeps its own pivots).
    pub fn apply_block_threads(
        &mut self,
        v: &mut [f64],
        k: usize,
        threads: usize,
    ) -> Result<(), SimError> {
        let n = self.n;
        if v.len() != n * k {
            return Err(SimError::DimensionMismatch {
                expected: n * k,
                found: v.len(),
            });
        }
        self.products += k;
        if self.cache.is_empty() && threads > 1 && self.steps.len() > 2 * threads {
            let rec = super::tangent_sweep::Recorded {
                sys: &self.sys,
                steps: &self.steps,
                stage_x: &self.stage_x,
                scale: &self.scale,
                pattern: &self.pattern,
            };
            super::tangent_sweep::apply_block_parallel(&rec, v, k, threads)?;
            self.factorizations += self.steps.len();
            self.jacobian_calls += 3 * self.steps.len();
            return Ok(());
        }
        let mut rhs = vec![0.0; 3 * n * k];
        let mut work = Vec::new();
        for s in 0..self.steps.len() {
            for (col, block) in v.chunks_exact(n).zip(rhs.chunks_exact_mut(3 * n)) {
                for i in 0..3 {
                    block[i * n..(i + 1) * n].copy_from_slice(col);
                }
            }
            if s < self.cache.len() {
                let mut w1 = vec![0.0; 3 * n];
                for block in rhs.chunks_exact_mut(3 * n) {
                    self.cache[s].solve(block, &mut w1);
                }
            } else {
                self.factor(s)?;
                self.sparse
                    .lu
                    .solve_columns(&mut rhs, k, &mut work)
                    .map_err(|_| SimError::SolverFailure {
                        t: self.steps[s].0,
                        why: "tangent step: singular stage matrix".into(),
                    })?;
            }
            for (col, block) in v.chunks_exact_mut(n).zip(rhs.chunks_exact(3 * n)) {
                col.copy_from_slice(&block[2 * n..]);
            }
        }
        Ok(())
    }

    /// Factor step `k`'s stage matrix into `sparse.lu` (kept in the cache while the budget
    /// lasts and `k` is the next uncached step).
    fn factor(&mut self, k: usize) -> Result<(), SimError> {
        let t0 = self.steps[k].0;
        factor_step(
            &self.sys,
            &self.stage_x,
            self.steps[k],
            k,
            &self.scale,
            &mut self.trip,
            &mut self.sparse,
        )?;
        self.jacobian_calls += 3;
        self.factorizations += 1;
        if k == self.cache.len() && self.cache_used < self.cache_budget {
            let kept = self
                .sparse
                .lu
                .snapshot()
                .map_err(|e| SimError::SolverFailure {
                    t: t0,
                    why: format!("tangent step: {e}"),
                })?;
            if self.cache_used + kept.bytes() <= self.cache_budget {
                self.cache_used += kept.bytes();
                self.cache.push(kept);
            } else {
                // full: keep no later step (the cache is the first steps, in order)
                self.cache_budget = 0;
            }
        }
        Ok(())
    }

    /// Record the Radau (sub)steps of the BDF step `[t0, t1]`.
    fn record(
        &mut self,
        t0: f64,
        t1: f64,
        substeps: usize,
        dense: &dyn Fn(f64, &mut [f64]),
    ) -> Result<(), SimError> {
        let (c, _) = radau3();
        let m = substeps.max(1);
        let n = self.n;
        for k in 0..m {
            let a = t0 + (t1 - t0) * k as f64 / m as f64;
            let b = if k + 1 == m {
                t1
            } else {
                t0 + (t1 - t0) * (k + 1) as f64 / m as f64
            };
            let h = b - a;
            if !(h > 0.0) {
                continue;
            }
            for cj in c {
                let start = self.stage_x.len();
                self.stage_x.resize(start + n, 0.0);
                dense(a + cj * h, &mut self.stage_x[start..]);
                if self.stage_x[start..].iter().any(|v| !v.is_finite()) {
                    return Err(SimError::SolverFailure {
                        t: a + cj * h,
                        why: "no dense output for the tangent stage".into(),
                    });
                }
            }
            self.steps.push((a, h));
        }
        Ok(())
    }
}

/// Factor the stage matrix of step `k` (at `(t0, h)`, stage states in `stage_x`) into
/// `sparse.lu`, with `trip` as the Jacobians' buffers.
pub(super) fn factor_step(
    sys: &ModelSystem<'_>,
    stage_x: &[f64],
    (t0, h): (f64, f64),
    k: usize,
    scale: &[f64],
    trip: &mut [Vec<(usize, usize, f64)>; 3],
    sparse: &mut SparseStage,
) -> Result<(), SimError> {
    let (c, a) = radau3();
    let n = scale.len();
    for j in 0..3 {
        let x = &stage_x[(3 * k + j) * n..(3 * k + j + 1) * n];
        scaled_triplets(sys, t0 + c[j] * h, x, scale, &mut trip[j]);
    }
    let stage = StageStep { n, h, a: &a, trip };
    stage
        .factor_sparse(sparse)
        .map_err(|e| SimError::SolverFailure {
            t: t0,
            why: format!("tangent step: {e}"),
        })
}

/// The flow `phi(x0, T)` and the recorded orbit for products with its monodromy, with
/// `substeps` Radau steps per BDF step and at most `cache_bytes` of stored stage factors.
pub fn flow_with_tangent<'m>(
    model: &'m dyn Model,
    p: &'m [f64],
    x0: &[f64],
    period: f64,
    opts: &SimOptions,
    substeps: usize,
    cache_bytes: usize,
) -> Result<(Vec<f64>, TangentFlow<'m>, SolverStats), SimError> {
    let n = model.n_states();
    let pattern = model.sparsity(p);
    let mut tf = TangentFlow {
        sys: ModelSystem { model, p },
        n,
        steps: Vec::new(),
        stage_x: Vec::new(),
        sparse: SparseStage::new(n, &pattern)?,
        pattern,
        cache: Vec::new(),
        cache_budget: cache_bytes,
        cache_used: 0,
        trip: Default::default(),
        scale: state_scale(model, p),
        products: 0,
        factorizations: 0,
        jacobian_calls: 0,
    };
    let mut on_step =
        |t0: f64, t1: f64, dense: &dyn Fn(f64, &mut [f64])| tf.record(t0, t1, substeps, dense);
    let (x_end, stats) = run_recorded(model, p, x0, period, opts, &mut on_step)?;
    Ok((x_end, tf, stats))
}
