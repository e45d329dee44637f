//! Newton-Krylov shooting: the limit cycle and its leading Floquet multipliers without the dense
//! monodromy matrix, for cycles above [`crate::sim::SHOOTING_MAX_STATES`] states.
//!
//! Same unknowns `(x0, T)`, scaling, section and inventory as [`crate::sim::shooting::shoot`]; the
//! Newton system is solved matrix-free by GMRES ([`crate::sim::gmres`]) on products `D^-1 Phi D v`
//! from [`crate::sim::tangent`] (one BDF run of the state per Newton iteration, then linear work on
//! the recorded steps).
//!
//! **Squaring the system.** The dense route solves the `(n + 2) x (n + 1)` system
//! (return map, section row, inventory row) by SVD least squares. It is consistent: with
//! mass states `c (Phi - I) = 0` and `c f = 0` (`c` = ones on the masses; the Radau
//! stage matrices keep `c` a left eigenvector with multiplier 1 exactly), so in scaled
//! form `sum_j s_j row_j = 0` over the mass rows `j` and any one mass row is the
//! combination `-(1/s_k) sum_{j != k} s_j row_j` of the others. Here the mass row with
//! the largest scale `s_k` (the best-conditioned recovery) is replaced by the inventory
//! row: a square `(n + 1) x (n + 1)` system with the same solution as the least squares
//! (its residual is zero). Without mass states the system is square already.
//!
//! **GMRES without preconditioner.** The operator is `D^-1 (Phi - I) D` bordered by the
//! field column and two rows: `-I` plus a low-rank part, because all but a handful of
//! multipliers are ~0 (stiff modes); GMRES converges in about as many products as there
//! are multipliers of order one, plus the border (a few dozen at n = 1000).

use stirling_dsl::Model;

use super::floquet_arnoldi::{leading_multipliers, ArnoldiOptions};
use super::gmres::gmres;
use super::integrate::SolverStats;
use super::shooting::{LimitCycle, MonodromyMethod, Section, ShootingOptions};
use super::tangent::{flow_with_tangent, TangentFlow};
use super::SimError;

/// Settings of the Krylov route.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KrylovOptions {
    /// GMRES stops at this residual relative to the Newton right-hand side.
    pub gmres_tol: f64,
    /// GMRES restart length.
    pub restart: usize,
    /// Most GMRES products per Newton iteration.
    pub max_products: usize,
    /// Memory for stored stage LU factors (bytes); past it the steps are refactored per
    /// product (same numbers, slower). Default: [`default_cache_bytes`].
    pub cache_bytes: usize,
    /// The leading multipliers.
    pub arnoldi: ArnoldiOptions,
}

impl Default for KrylovOptions {
    fn default() -> Self {
        Self {
            gmres_tol: 1e-10,
            restart: 60,
            max_products: 300,
            cache_bytes: default_cache_bytes(),
            arnoldi: ArnoldiOptions::default(),
        }
    }
}

/// Half the memory the system reports available (`/proc/meminfo`), at most 8 GiB; 2 GiB
/// where that cannot be read. nsection n = 1000 stores all of its ~1800 steps in ~5 GB;
/// past the budget every product refactors the remaining steps (a few times slower).
pub fn default_cache_bytes() -> usize {
    let available_kb = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find(|l| l.starts_with("MemAvailable:"))
            .and_then(|l| l.split_whitespace().nth(1)?.parse::<usize>().ok())
    });
    match available_kb {
        Some(kb) => (kb * 512).min(8 << 30),
        None => 2 << 30,
    }
}

/// The square Newton system at one iterate (see the module doc).
pub(super) struct Bordered<'a> {
    sec: &'a Section,
    /// `f / s * T` at the return point.
    field: Vec<f64>,
    /// The mass row replaced by the inventory row.
    drop: Option<usize>,
}

impl Bordered<'_> {
    pub(super) fn new<'a>(sec: &'a Section, f: &[f64], t_per: f64) -> Bordered<'a> {
        let field = f.iter().zip(&sec.s).map(|(f, s)| f / s * t_per).collect();
        let drop = sec
            .masses
            .iter()
            .copied()
            .max_by(|&a, &b| sec.s[a].total_cmp(&sec.s[b]));
        Bordered { sec, field, drop }
    }

    /// Right-hand side from the scaled return residual `r` at `x`.
    pub(super) fn rhs(&self, r: &[f64], x: &[f64]) -> Vec<f64> {
        let (s, iy) = (&self.sec.s, self.sec.iy);
        let mut b: Vec<f64> = r.iter().map(|v| -v).collect();
        if let Some(k) = self.drop {
            let m: f64 = self.sec.masses.iter().map(|&j| x[j]).sum();
            b[k] = -(m - self.sec.m_total) / self.sec.m_total;
        }
        b.push(-x[iy] / s[iy]);
        b
    }

    /// `out = A z` (`z = (dx / s, dT / T)`), the monodromy's product `D^-1 Phi D v` by `phi`.
    pub(super) fn apply(
        &self,
        phi: &mut dyn FnMut(&mut [f64]) -> Result<(), SimError>,
        z: &[f64],
        out: &mut [f64],
    ) -> Result<(), SimError> {
        let n = self.field.len();
        out[..n].copy_from_slice(&z[..n]);
        phi(&mut out[..n])?;
        for i in 0..n {
            out[i] += self.field[i] * z[n] - z[i];
        }
        if let Some(k) = self.drop {
            let sec = self.sec;
            out[k] = sec.masses.iter().map(|&j| sec.s[j] * z[j]).sum::<f64>() / sec.m_total;
        }
        out[n] = z[self.sec.iy];
        Ok(())
    }
}

fn add_tangent(stats: &mut SolverStats, tf: &TangentFlow) {
    stats.jacobian_calls += tf.jacobian_calls;
    stats.lu_factorizations += tf.factorizations;
}

/// Work counters of [`shoot_krylov_counted`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KrylovCounts {
    /// Monodromy-vector products by GMRES, all Newton iterations.
    pub gmres_products: usize,
    /// Products by the Arnoldi run of the multipliers.
    pub arnoldi_products: usize,
    /// Radau steps of the last orbit, and how many kept their stage factors.
    pub steps: usize,
    pub cached_steps: usize,
}

/// Newton-Krylov shooting from `(x0, period)`; the cycle's `monodromy` is empty and
/// `floquet` holds the leading multipliers ([`ArnoldiOptions::k`], largest modulus first).
pub fn shoot_krylov(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &ShootingOptions,
    kopts: &KrylovOptions,
) -> Result<LimitCycle, SimError> {
    Ok(shoot_krylov_counted(model, p, x0, period, opts, kopts)?.0)
}

/// [`shoot_krylov`] with its work counters.
pub fn shoot_krylov_counted(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &ShootingOptions,
    kopts: &KrylovOptions,
) -> Result<(LimitCycle, KrylovCounts), SimError> {
    let n = model.n_states();
    let sec = Section::of(model, p, x0)?;
    let substeps = match opts.monodromy {
        MonodromyMethod::Radau { substeps } => substeps,
        MonodromyMethod::Variational => 1,
    };
    let (mut x, mut t_per) = (x0.to_vec(), period);
    let mut stats = SolverStats::default();
    let mut f = vec![0.0; n];
    let mut res = f64::INFINITY;
    let mut counts = KrylovCounts::default();
    for it in 1..=opts.max_iter {
        let (phi, mut tf, st) =
            flow_with_tangent(model, p, &x, t_per, &opts.sim, substeps, kopts.cache_bytes)?;
        stats.add(&st);
        let r: Vec<f64> = (0..n).map(|i| (phi[i] - x[i]) / sec.s[i]).collect();
        res = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if res < opts.tol {
            let (floquet, products) = leading_multipliers(&mut |v| tf.apply(v), n, &kopts.arnoldi)?;
            add_tangent(&mut stats, &tf);
            counts.arnoldi_products = products;
            (counts.steps, counts.cached_steps) = (tf.steps(), tf.cached_steps());
            let cycle = LimitCycle {
                x0: x,
                period: t_per,
                monodromy: vec![],
                floquet,
                iterations: it,
                residual: res,
                stats,
            };
            return Ok((cycle, counts));
        }
        model.rhs(p, &phi, t_per, &mut f);
        let sys = Bordered::new(&sec, &f, t_per);
        let b = sys.rhs(&r, &x);
        let mut op = |z: &[f64], out: &mut [f64]| sys.apply(&mut |v| tf.apply(v), z, out);
        let sol = gmres(
            &mut op,
            &b,
            kopts.gmres_tol,
            kopts.restart,
            kopts.max_products,
        )?;
        add_tangent(&mut stats, &tf);
        counts.gmres_products += sol.iterations;
        if !(sol.relative_residual < 1e-3) {
            return Err(SimError::ShootingFailed {
                iterations: it,
                residual: res,
                why: format!(
                    "GMRES reached only {:.2e} relative residual in {} products",
                    sol.relative_residual, sol.iterations
                ),
            });
        }
        for j in 0..n {
            x[j] += sol.x[j] * sec.s[j];
        }
        t_per *= 1.0 + sol.x[n];
        if !(t_per > 0.0) {
            return Err(SimError::ShootingFailed {
                iterations: it,
                residual: res,
                why: "the period became non-positive".into(),
            });
        }
    }
    Err(SimError::ShootingFailed {
        iterations: opts.max_iter,
        residual: res,
        why: "Newton did not converge".into(),
    })
}
