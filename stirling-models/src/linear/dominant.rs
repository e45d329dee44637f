//! The dominant (rightmost) poles of a large model by shift-invert Arnoldi on the sparse
//! Jacobian, without forming `T' J T`.
//!
//! **Operator.** `(J_s - sigma I)^-1` with `J_s = D^-1 J D` (`D` the state scales of
//! [`crate::linear::equilibrium::state_scales`]: a similarity, so the same eigenvalues, but Krylov
//! vectors whose entries are comparable across pressures, masses and positions), applied by a
//! complex faer sparse LU ([`crate::linear::sparse::ShiftedSolver`]; the symbolic analysis is
//! shared by all shifts). A Ritz value `theta` of the operator is the pole `lambda = sigma +
//! 1/theta`.
//!
//! **Inventory.** With mass states, `c J = 0` (`c` = ones on the masses), so `ker c` is
//! invariant under `J` and under `(J - sigma I)^-1` (`sigma != 0`). The start vector is put in
//! `ker c` and every new Krylov vector is projected back onto it (only round-off is removed), so
//! the Ritz values are poles of the reduced `T' J T` and the inventory's zero is never returned.
//!
//! **Arnoldi.** `m` steps
//! ([`DominantOptions::krylov`](crate::linear::dominant::DominantOptions::krylov)) with full
//! reorthogonalization (classical Gram-Schmidt, twice), the Ritz pairs from the eigendecomposition
//! of the `m x m` Hessenberg matrix. A Ritz pair `(theta, x = V y)` counts as converged when its
//! Ritz residual relative to `theta`, `|OP x - theta x| / |theta x| = |h_{m+1,m} y_m| / (|theta|
//! |y|)`, is below [`DominantOptions::tol`](crate::linear::dominant::DominantOptions::tol): that is
//! the relative accuracy of `theta`, i.e. of `lambda - sigma` (ARPACK's rule). A residual of `J_s`
//! itself relative to `|lambda|` cannot go below `eps |J_s| / |lambda|` (`|J_s|` ~ 1e7 1/s from the
//! pressure-equalization modes, 1e2 for the working pair) and would reject the working poles at
//! large n.
//!
//! **Shift rule.** The working frequency is not known in advance. 1) Scan: shifts `j w_k`, `w_k`
//! log-spaced over
//! [`DominantOptions::band_rad_s`](crate::linear::dominant::DominantOptions::band_rad_s)
//! ([`DominantOptions::per_decade`](crate::linear::dominant::DominantOptions::per_decade) per
//! decade), one Arnoldi run each; every converged Ritz value joins a pool (lower-half-plane values
//! by their conjugates, duplicates merged by the smaller residual). 2) Refine: at the rightmost
//! pole of the pool, shifted by `1e-3 |lambda|` along the imaginary axis, one more Arnoldi run; its
//! converged values replace their neighbours in the pool. 3) Keep the `k` rightmost poles of the
//! pool (a conjugate pair is never split, so up to `k + 1`). The result is the rightmost of what
//! lies near the band; a pole far from every shift (for example a very fast real pressure mode) is
//! not sought: the engine's working modes are not those.
//!
//! No maintained Rust crate does this on faer matrices (`arpack` 0.0.x binds a system
//! ARPACK-NG and offers one eigenpair of fixed kind), hence this module.

use faer::{c64, Mat};
use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use super::equilibrium::{mass_states, state_scales};
use super::poles::{to_poles, Pole};
use super::sparse::{ShiftedSolver, SparseMatrix};
use super::LinearError;

/// Settings of [`dominant_poles_with`].
#[derive(Clone, Debug, PartialEq)]
pub struct DominantOptions {
    /// Poles to keep (a pair is never split).
    pub k: usize,
    /// Arnoldi steps per shift.
    pub krylov: usize,
    /// Scanned band `(w_lo, w_hi)` in rad/s.
    pub band_rad_s: (f64, f64),
    /// Scan shifts per decade.
    pub per_decade: usize,
    /// Ritz residual for convergence (relative, see the module doc).
    pub tol: f64,
}

impl Default for DominantOptions {
    fn default() -> Self {
        Self {
            k: 8,
            krylov: 30,
            band_rad_s: (1.0, 1e4),
            per_decade: 2,
            tol: 1e-10,
        }
    }
}

/// The dominant poles and how they were found.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DominantPoles {
    /// Sorted by decreasing real part, pairs symmetric (as [`to_poles`]).
    pub poles: Vec<Pole>,
    /// The shifts used, `(re, im)`: the scan, then the refinement.
    pub shifts: Vec<(f64, f64)>,
    /// Arnoldi steps (sparse solves) over all shifts.
    pub iterations: usize,
    /// The largest Ritz residual among the returned poles.
    pub residual: f64,
}

/// A converged Ritz value.
#[derive(Clone, Copy, Debug)]
struct Ritz {
    lambda: c64,
    residual: f64,
}

/// The `k` dominant poles of `model` at `x_eq` (default options otherwise).
pub fn dominant_poles(
    model: &dyn Model,
    p: &[f64],
    x_eq: &[f64],
    k: usize,
) -> Result<DominantPoles, LinearError> {
    let a = SparseMatrix {
        n: x_eq.len(),
        entries: model.jacobian_triplets(p, x_eq, 0.0),
    };
    let opts = DominantOptions {
        k,
        ..Default::default()
    };
    dominant_poles_with(&a, &state_scales(model, x_eq), &mass_states(model), &opts)
}

/// The dominant poles of `a` (scaled by `scales`; `masses`: the inventory, may be empty).
pub fn dominant_poles_with(
    a: &SparseMatrix,
    scales: &[f64],
    masses: &[usize],
    opts: &DominantOptions,
) -> Result<DominantPoles, LinearError> {
    if a.entries.iter().any(|e| !e.2.is_finite()) {
        return Err(LinearError::NonFinite { what: "Jacobian" });
    }
    let js = a.scaled(scales);
    let w: Vec<(usize, f64)> = masses.iter().map(|&i| (i, scales[i])).collect();
    let mut solver = ShiftedSolver::new(&js).map_err(|e| lu_error(c64::new(0.0, 0.0), e))?;
    let mut run = Run {
        js: &js,
        js_max: js.max_abs(),
        w: &w,
        opts,
        pool: Vec::new(),
        shifts: Vec::new(),
        iterations: 0,
        worst: (c64::new(0.0, 0.0), f64::INFINITY),
    };
    // the scan's shifts are independent: factored and run in parallel, their Ritz values
    // merged in the shifts' order (the same pool as one after the other)
    let scans: Vec<Result<Scan, LinearError>> = {
        use rayon::prelude::*;
        let run = &run;
        scan_shifts(opts)
            .into_par_iter()
            .map(|sigma| run.scan(&mut solver.clone(), sigma))
            .collect()
    };
    for scan in scans {
        run.absorb(scan?);
    }
    let best = run.rightmost().ok_or(LinearError::NoDominantPoles {
        shift_re: run.worst.0.re,
        shift_im: run.worst.0.im,
        residual: run.worst.1,
    })?;
    let refine = best + c64::new(0.0, 1e-3 * best.norm().max(1.0));
    run.at(&mut solver, refine)?;
    Ok(run.finish())
}

fn lu_error(sigma: c64, e: super::sparse::SparseLuError) -> LinearError {
    LinearError::ShiftFactor {
        shift_re: sigma.re,
        shift_im: sigma.im,
        why: e.why,
    }
}

/// `j w_k`, log-spaced over the band.
fn scan_shifts(opts: &DominantOptions) -> Vec<c64> {
    let (lo, hi) = opts.band_rad_s;
    let decades = (hi / lo).log10().max(0.0);
    let count = ((decades * opts.per_decade as f64).round() as usize).max(1);
    (0..=count)
        .map(|i| c64::new(0.0, lo * 10f64.powf(decades * i as f64 / count as f64)))
        .collect()
}

/// The condition number assumed when merging Ritz values (see [`Run::merge`]).
const MERGE_KAPPA: f64 = 1e3;

/// The state of one dominant-pole search.
struct Run<'a> {
    js: &'a SparseMatrix,
    /// `max |J_s|`.
    js_max: f64,
    w: &'a [(usize, f64)],
    opts: &'a DominantOptions,
    pool: Vec<Ritz>,
    shifts: Vec<(f64, f64)>,
    iterations: usize,
    /// The shift with the smallest Ritz residual so far (named by the error if none converges).
    worst: (c64, f64),
}

/// One Arnoldi run: its shift, steps and Ritz values.
struct Scan {
    sigma: c64,
    steps: usize,
    ritz: Vec<Ritz>,
}

impl Run<'_> {
    /// One Arnoldi run at `sigma` (factoring `solver` there).
    fn scan(&self, solver: &mut ShiftedSolver, sigma: c64) -> Result<Scan, LinearError> {
        solver.factor(sigma).map_err(|e| lu_error(sigma, e))?;
        let v0 = start_vector(self.js.n, self.w);
        let dim = self.js.n - usize::from(!self.w.is_empty());
        let kr = arnoldi(solver, v0, self.opts.krylov.min(dim), self.w);
        Ok(Scan {
            sigma,
            steps: kr.steps,
            ritz: ritz_pairs(&kr, sigma)?,
        })
    }

    /// One Arnoldi run at `sigma`; its converged Ritz values join the pool.
    fn at(&mut self, solver: &mut ShiftedSolver, sigma: c64) -> Result<(), LinearError> {
        let scan = self.scan(solver, sigma)?;
        self.absorb(scan);
        Ok(())
    }

    /// A run's converged Ritz values join the pool.
    fn absorb(&mut self, Scan { sigma, steps, ritz }: Scan) {
        self.shifts.push((sigma.re, sigma.im));
        self.iterations += steps;
        let smallest = ritz
            .iter()
            .map(|r| r.residual)
            .fold(f64::INFINITY, f64::min);
        if smallest < self.worst.1 {
            self.worst = (sigma, smallest);
        }
        for r in ritz.into_iter().filter(|r| r.residual <= self.opts.tol) {
            self.merge(r);
        }
    }

    /// Add `r` (upper half plane), replacing a duplicate with a larger residual.
    fn merge(&mut self, mut r: Ritz) {
        if r.lambda.im < 0.0 {
            r.lambda = r.lambda.conj();
        }
        if r.lambda.im.abs() <= 1e-8 * r.lambda.norm() {
            r.lambda.im = 0.0;
        }
        // two values closer than the attainable accuracy of a pole, about `eps |J_s|` times a
        // condition number (`|J_s|` grows like n^2: at n = 10,000 two shifts returned the
        // working pair 1.6e-4 apart and it was listed twice), are one pole
        let floor = MERGE_KAPPA * f64::EPSILON * self.js_max;
        let near = |q: &Ritz| {
            (q.lambda - r.lambda).norm() <= (1e-6 * r.lambda.norm()).max(floor).max(1e-12)
        };
        match self.pool.iter_mut().find(|q| near(q)) {
            Some(q) if q.residual > r.residual => *q = r,
            Some(_) => {}
            None => self.pool.push(r),
        }
    }

    fn rightmost(&self) -> Option<c64> {
        self.pool
            .iter()
            .max_by(|a, b| a.lambda.re.total_cmp(&b.lambda.re))
            .map(|r| r.lambda)
    }

    fn finish(mut self) -> DominantPoles {
        self.pool
            .sort_by(|a, b| b.lambda.re.total_cmp(&a.lambda.re));
        let (mut ev, mut residual) = (Vec::new(), 0.0f64);
        for r in &self.pool {
            if ev.len() >= self.opts.k {
                break;
            }
            residual = residual.max(r.residual);
            ev.push((r.lambda.re, r.lambda.im));
            if r.lambda.im != 0.0 {
                ev.push((r.lambda.re, -r.lambda.im));
            }
        }
        DominantPoles {
            poles: to_poles(ev),
            shifts: self.shifts,
            iterations: self.iterations,
            residual,
        }
    }
}

/// A fixed start vector in `ker w'` (deterministic: the same poles every run).
fn start_vector(n: usize, w: &[(usize, f64)]) -> Vec<c64> {
    let mut v: Vec<c64> = (0..n)
        .map(|i| c64::new(1.0 + 0.5 * (i as f64 * 0.7).sin(), 0.0))
        .collect();
    project(&mut v, w);
    v
}

/// Remove the component along `w` (the inventory constraint in scaled coordinates).
fn project(v: &mut [c64], w: &[(usize, f64)]) {
    let ww: f64 = w.iter().map(|(_, d)| d * d).sum();
    if ww == 0.0 {
        return;
    }
    let wv: c64 = w.iter().map(|&(i, d)| v[i] * d).sum();
    for &(i, d) in w {
        v[i] -= wv * (d / ww);
    }
}

fn norm(v: &[c64]) -> f64 {
    v.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt()
}

/// `sum conj(a_i) b_i`.
fn dot(a: &[c64], b: &[c64]) -> c64 {
    a.iter().zip(b).map(|(a, b)| a.conj() * b).sum()
}

/// The Hessenberg matrix of an Arnoldi factorization `OP V_m = V_{m+1} H`.
struct Krylov {
    /// `(m + 1) x m`, column-major by Arnoldi step.
    h: Vec<Vec<c64>>,
    steps: usize,
}

/// `m` Arnoldi steps of the factored shift-invert operator from `v0`, stopping early on an
/// invariant subspace (or a failed solve).
fn arnoldi(solver: &ShiftedSolver, v0: Vec<c64>, m: usize, w: &[(usize, f64)]) -> Krylov {
    let n0 = norm(&v0);
    let mut v = vec![v0.into_iter().map(|z| z / n0).collect::<Vec<_>>()];
    let mut h: Vec<Vec<c64>> = Vec::new();
    let mut steps = 0;
    while steps < m {
        let Some(mut x) = solver.solve(&v[steps]) else {
            break;
        };
        steps += 1;
        project(&mut x, w);
        let mut col = vec![c64::new(0.0, 0.0); steps + 1];
        for _ in 0..2 {
            for (k, vk) in v.iter().enumerate() {
                let c = dot(vk, &x);
                col[k] += c;
                for (xi, vi) in x.iter_mut().zip(vk) {
                    *xi -= c * vi;
                }
            }
        }
        let beta = norm(&x);
        col[steps] = c64::new(beta, 0.0);
        h.push(col);
        let scale = col_scale(&h[steps - 1]);
        if !(beta > 1e-14 * scale) {
            break;
        }
        v.push(x.into_iter().map(|z| z / beta).collect());
    }
    Krylov { h, steps }
}

fn col_scale(col: &[c64]) -> f64 {
    col.iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE)
}

/// The Ritz values of a factorization as poles, with their Ritz residuals
/// `|OP x - theta x| / |theta| = |h_{m+1,m}| |y_m| / |theta|` (unit `y`): the relative accuracy of
/// `theta`, hence of `lambda - sigma`.
fn ritz_pairs(kr: &Krylov, sigma: c64) -> Result<Vec<Ritz>, LinearError> {
    let m = kr.steps;
    if m == 0 {
        return Ok(Vec::new());
    }
    let hm = Mat::<c64>::from_fn(m, m, |i, j| kr.h[j].get(i).copied().unwrap_or_default());
    let eig = hm
        .eigen()
        .map_err(|e| LinearError::Eigen(format!("{e:?}")))?;
    let (s, u) = (eig.S().column_vector(), eig.U());
    let beta = kr.h[m - 1][m].norm();
    let big = (0..m).map(|i| s[i].norm()).fold(0.0f64, f64::max);
    let mut out = Vec::with_capacity(m);
    for i in 0..m {
        let theta = s[i];
        // theta ~ 0 is round-off (a pole at infinity), never a pole near the shift.
        if !(theta.norm() > 1e-10 * big) {
            continue;
        }
        let lambda = sigma + c64::new(1.0, 0.0) / theta;
        let y: f64 = (0..m).map(|j| u[(j, i)].norm_sqr()).sum::<f64>().sqrt();
        let residual = beta * u[(m - 1, i)].norm() / (y * theta.norm());
        if residual.is_finite() && lambda.re.is_finite() && lambda.im.is_finite() {
            out.push(Ritz { lambda, residual });
        }
    }
    Ok(out)
}
