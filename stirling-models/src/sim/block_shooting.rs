//! Block shooting: the limit cycle and its leading Floquet multipliers with memory that grows
//! linearly in the number of states (no stored stage factors), for large cycles.
//!
//! Same unknowns `(x0, T)`, scaling, section, inventory row and square Newton system as the
//! Newton-Krylov route ([`crate::sim::krylov_shooting`]), and the same discrete monodromy (3-stage
//! Radau IIA on the recorded BDF steps, [`crate::sim::tangent`]); what differs is how the
//! monodromy is applied and how often:
//!
//! - **Products by blocks.** A product factors every step's `3n x 3n` stage matrix; the Krylov
//!   route keeps those factors for its ~50 single-vector products (5 GB at nsection n = 1000).
//!   Here the monodromy is applied to a block of columns per sweep over the steps
//!   ([`TangentFlow::apply_block`](crate::sim::tangent::TangentFlow::apply_block): each step factored once for all columns, nothing kept), and a
//!   few sweeps of block Arnoldi ([`crate::sim::block_arnoldi`]) give the space the multipliers
//!   live in. Memory: the recorded stage states (`3 n` per step) and a few dozen vectors.
//! - **Newton on a low-rank surrogate.** All but a handful of multipliers are ~0 (the stiff
//!   modes), so `Phi` is numerically of low rank. Two block sweeps from the block `(r, f, random)`
//!   (residual, field, random columns) on an orbit recorded at a looser tolerance
//!   ([`BlockOptions::surrogate_rtol`]: a third of the steps) give `Phi ~ Z_+ H Z^T`; GMRES solves
//!   the Newton system with that surrogate (products of `O(n)` cost), and the residual is always
//!   the full-accuracy return map, so the fixed point is the exact one and only the rate of
//!   convergence depends on the surrogate. A residual that leaves the surrogate's space (after
//!   the first step the residual has a part outside `Z`, which the surrogate maps to zero while
//!   `Phi` does not: the chord steps then diverged tenfold per step at n = 1000) gets its product
//!   by a difference of two full-accuracy runs (one more BDF run, no sweep), added to the
//!   surrogate as a rank-one term; the surrogate is rebuilt after
//!   [`BlockOptions::max_chord`] steps or when the residual grew tenfold.
//! - **Multipliers on the converged orbit.** Once the residual is below tolerance the orbit is
//!   recorded at the shot's tolerance and block Arnoldi runs on the same discrete `Phi` as the
//!   dense route, from the surrogate's dominant images (already near the slow subspace), until the
//!   leading Ritz values' residuals (from `H`, [`BlockArnoldi::ritz_residuals`](crate::sim::block_arnoldi::BlockArnoldi::ritz_residuals)) or their change
//!   over the last sweep fall below [`BlockOptions::tol`]: two sweeps at n = 100 and 1000. The
//!   multipliers equal the dense route's to round-off times their conditioning; the double
//!   multiplier 1 (a Jordan block) splits by the square root of the Ritz residual, or of the
//!   discrete monodromy's own departure from the double 1, whichever is larger (about `1e-7`
//!   at n = 100, `1e-5` at n = 1000 by every route).

use stirling_dsl::Model;

use super::block_arnoldi::{pseudo_random_block, BlockArnoldi};
use super::floquet_arnoldi::leading;
use super::gmres::gmres;
use super::integrate::{SimOptions, SolverStats};
use super::krylov_shooting::Bordered;
use super::monodromy::run_recorded;
use super::shooting::{LimitCycle, MonodromyMethod, Section, ShootingOptions};
use super::shot_update::{run_from_update, Update, MAX_HALVINGS};
use super::tangent::{flow_with_tangent, TangentFlow};
use super::SimError;

/// Settings of the block route.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockOptions {
    /// Columns per sweep of the surrogate, and of the multipliers (more: the Ritz values of the
    /// double multiplier 1, a Jordan block, split by the square root of their residual).
    pub block: usize,
    pub final_block: usize,
    /// Block sweeps of the Newton surrogate.
    pub surrogate_sweeps: usize,
    /// Integrator tolerance of the surrogate's orbit (the shot's own when that is looser).
    pub surrogate_rtol: f64,
    /// Newton steps on one surrogate before it is rebuilt at the current iterate (also rebuilt
    /// when the residual grew tenfold over the one it was built at).
    pub max_chord: usize,
    /// Step (scaled) of the difference that gives the product along a residual's new direction.
    pub difference_step: f64,
    /// Multipliers to return (a conjugate pair is never split, so up to `k + 1`).
    pub k: usize,
    /// Most block sweeps for the multipliers.
    pub max_sweeps: usize,
    /// The multipliers are converged when the `k` leading Ritz values moved by less than this
    /// (relative to `max(1, |mu|)`) in the last sweep.
    pub tol: f64,
    /// GMRES on the surrogate: relative residual, restart length, most products.
    pub gmres_tol: f64,
    pub restart: usize,
    pub max_products: usize,
}

impl Default for BlockOptions {
    fn default() -> Self {
        Self {
            block: 10,
            final_block: 12,
            surrogate_sweeps: 2,
            surrogate_rtol: 1e-7,
            max_chord: 4,
            difference_step: 1e-5,
            k: 8,
            max_sweeps: 8,
            tol: 1e-9,
            gmres_tol: 1e-12,
            restart: 100,
            max_products: 400,
        }
    }
}

/// Work counters of [`shoot_block_counted`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BlockCounts {
    /// Surrogates built, and their block sweeps.
    pub surrogates: usize,
    pub surrogate_sweeps: usize,
    /// Block sweeps on the converged orbit (the multipliers), and the columns they applied.
    pub sweeps: usize,
    pub columns: usize,
    /// Radau steps of the converged orbit and of the last surrogate's orbit.
    pub steps: usize,
    pub surrogate_steps: usize,
    /// Products by a difference of two runs (one extra run each).
    pub differences: usize,
}

fn add_tangent(stats: &mut SolverStats, tf: &TangentFlow) {
    stats.jacobian_calls += tf.jacobian_calls;
    stats.lu_factorizations += tf.factorizations;
}

fn substeps(opts: &ShootingOptions) -> usize {
    match opts.monodromy {
        MonodromyMethod::Radau { substeps } => substeps,
        MonodromyMethod::Variational => 1,
    }
}

/// The Newton surrogate of `D^-1 Phi D`: the block Arnoldi's `Z_+ H Z^T`, plus the products
/// `u = Phi w` along directions `w` orthonormal to `Z` (and to each other) found by a
/// difference of two full-accuracy runs (one run each).
struct Surrogate {
    ba: BlockArnoldi,
    extra: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Surrogate {
    fn apply(&self, v: &mut [f64]) {
        let c: Vec<f64> = self.extra.iter().map(|(w, _)| dot(w, v)).collect();
        self.ba.apply_low_rank(v);
        for ((_, u), ci) in self.extra.iter().zip(c) {
            v.iter_mut().zip(u).for_each(|(a, b)| *a += ci * b);
        }
    }

    /// The part of `r` outside the surrogate's directions, unit length (`None` when negligible).
    fn new_direction(&self, r: &[f64]) -> Option<Vec<f64>> {
        let mut w = r.to_vec();
        let r0 = dot(r, r).sqrt();
        for _ in 0..2 {
            self.ba.orthogonalize(&mut w);
            for (e, _) in &self.extra {
                let c = dot(&w, e);
                w.iter_mut().zip(e).for_each(|(a, b)| *a -= c * b);
            }
        }
        let nw = dot(&w, &w).sqrt();
        (nw > 1e-3 * r0 && nw > 0.0).then(|| w.iter().map(|x| x / nw).collect())
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Block shooting from `(x0, period)`; the cycle's `monodromy` is empty and `floquet` holds the
/// leading multipliers ([`BlockOptions::k`], largest modulus first).
pub fn shoot_block(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &ShootingOptions,
    bopts: &BlockOptions,
) -> Result<LimitCycle, SimError> {
    Ok(shoot_block_counted(model, p, x0, period, opts, bopts)?.0)
}

/// The surrogate `Z_+ H Z^T` of `D^-1 Phi D` at `(x, t_per)` from the block `(r, field, random)`.
fn surrogate(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    t_per: f64,
    opts: &ShootingOptions,
    bopts: &BlockOptions,
    seed_cols: [&[f64]; 2],
    stats: &mut SolverStats,
    counts: &mut BlockCounts,
) -> Result<BlockArnoldi, SimError> {
    let n = x.len();
    let tol = opts.sim.rtol.max(bopts.surrogate_rtol);
    let coarse = SimOptions {
        rtol: tol,
        atol: opts.sim.atol.max(tol),
        ..opts.sim
    };
    let (_, mut tf, st) = flow_with_tangent(model, p, x, t_per, &coarse, substeps(opts), 0)?;
    stats.add(&st);
    let k = bopts.block.max(3);
    let mut start = seed_cols.concat();
    start.extend(pseudo_random_block(n, k - 2, 1));
    let mut ba = BlockArnoldi::new(n, &start, k)?;
    for _ in 0..bopts.surrogate_sweeps.max(1) {
        counts.surrogate_sweeps += 1;
        if !ba.sweep(&mut |v, c| tf.apply_block(v, c))? {
            break;
        }
    }
    add_tangent(stats, &tf);
    counts.surrogates += 1;
    counts.surrogate_steps = tf.steps();
    Ok(ba)
}

/// The leading multipliers on the orbit of `(x, t_per)` by block Arnoldi from `start`.
fn multipliers(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    t_per: f64,
    opts: &ShootingOptions,
    bopts: &BlockOptions,
    start: Vec<f64>,
    stats: &mut SolverStats,
    counts: &mut BlockCounts,
) -> Result<Vec<(f64, f64)>, SimError> {
    let n = x.len();
    let (_, mut tf, st) = flow_with_tangent(model, p, x, t_per, &opts.sim, substeps(opts), 0)?;
    stats.add(&st);
    counts.steps = tf.steps();
    let mut ba = BlockArnoldi::new(n, &start, start.len() / n.max(1))?;
    let mut last: Vec<(f64, f64)> = Vec::new();
    let mut moved = f64::INFINITY;
    for _ in 0..bopts.max_sweeps.max(1) {
        counts.sweeps += 1;
        let before = ba.products;
        let grew = ba.sweep(&mut |v, c| tf.apply_block(v, c))?;
        counts.columns += ba.products - before;
        let with_res = ba.ritz_residuals();
        let ritz: Vec<(f64, f64)> = with_res.iter().map(|v| v.0).collect();
        let now = leading(&ritz, bopts.k);
        let resid = with_res[..now.len()]
            .iter()
            .map(|(t, r)| r / t.0.hypot(t.1).max(1.0))
            .fold(0.0, f64::max);
        moved = moved_from(&now, &last);
        last = now;
        if moved < bopts.tol || resid < bopts.tol || !grew || ba.applied() >= n {
            add_tangent(stats, &tf);
            return Ok(last);
        }
    }
    Err(SimError::FloquetNotConverged {
        products: ba.products,
        change: moved,
    })
}

/// How far the values `now` moved from `last`: the largest distance of one of them to the
/// nearest of `last`, relative to `max(1, |mu|)` (infinite when `last` is empty). Nearest, not
/// by position: the two members of a pair, or a pair and a real value of the same modulus,
/// swap places in the sorted lists from one sweep to the next.
fn moved_from(now: &[(f64, f64)], last: &[(f64, f64)]) -> f64 {
    now.iter()
        .map(|a| {
            let near = last
                .iter()
                .map(|b| (a.0 - b.0).hypot(a.1 - b.1))
                .fold(f64::INFINITY, f64::min);
            near / a.0.hypot(a.1).max(1.0)
        })
        .fold(if last.is_empty() { f64::INFINITY } else { 0.0 }, f64::max)
}

/// [`shoot_block`] with its work counters.
pub fn shoot_block_counted(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    period: f64,
    opts: &ShootingOptions,
    bopts: &BlockOptions,
) -> Result<(LimitCycle, BlockCounts), SimError> {
    let n = model.n_states();
    if x0.len() != n {
        return Err(SimError::DimensionMismatch {
            expected: n,
            found: x0.len(),
        });
    }
    let sec = Section::of(model, p, x0)?;
    let (mut x, mut t_per) = (x0.to_vec(), period);
    let mut stats = SolverStats::default();
    let mut counts = BlockCounts::default();
    let mut f = vec![0.0; n];
    let mut sur: Option<Surrogate> = None;
    let mut res = f64::INFINITY;
    // steps on the current surrogate, and the residual it was built at
    let (mut chord, mut at_build) = (0usize, f64::INFINITY);
    // the last Newton update (in state units, and the period's factor), and its halvings
    let mut last: Option<Update> = None;
    for it in 1..=opts.max_iter {
        let moved = last.as_ref().map(|u| u.largest);
        let (phi, st) = run_from_update(model, p, (&mut x, &mut t_per), opts, last.as_mut())
            .map_err(|e| match (e, moved) {
                (e, None) | (e @ SimError::ShootingFailed { .. }, _) => e,
                (e, Some((j, by))) => SimError::ShootingFailed {
                    iterations: it,
                    residual: res,
                    why: format!(
                        "the return map failed from Newton's update (which moved `{}` most, by {by:.3e} of its scale) and from {MAX_HALVINGS} halvings of it: {e}",
                        model.states().get(j).map_or("?", |s| s.name.as_str())
                    ),
                },
            })?;
        stats.add(&st);
        let r: Vec<f64> = (0..n).map(|i| (phi[i] - x[i]) / sec.s[i]).collect();
        res = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if res < opts.tol {
            let k = bopts.final_block.max(1);
            let mut start = sur.as_ref().map_or(Vec::new(), |b| b.ba.dominant_images(k));
            let have = start.len() / n.max(1);
            start.extend(pseudo_random_block(n, k.saturating_sub(have), 2));
            let floquet = multipliers(
                model,
                p,
                &x,
                t_per,
                opts,
                bopts,
                start,
                &mut stats,
                &mut counts,
            )?;
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
        chord += 1;
        if sur.is_none() || chord > bopts.max_chord || res > 10.0 * at_build {
            let field: Vec<f64> = f
                .iter()
                .zip(&sec.s)
                .map(|(fi, si)| fi / si * t_per)
                .collect();
            let ba = surrogate(
                model,
                p,
                &x,
                t_per,
                opts,
                bopts,
                [&r, &field],
                &mut stats,
                &mut counts,
            )?;
            sur = Some(Surrogate {
                ba,
                extra: Vec::new(),
            });
            (chord, at_build) = (0, res);
        } else if let Some(sg) = sur.as_mut() {
            // the residual's new direction, by a difference of two runs
            if let Some(w) = sg.new_direction(&r) {
                let eps = bopts.difference_step;
                let xe: Vec<f64> = (0..n).map(|j| x[j] + eps * w[j] * sec.s[j]).collect();
                let (pe, st) =
                    run_recorded(model, p, &xe, t_per, &opts.sim, &mut |_, _, _| Ok(()))?;
                stats.add(&st);
                counts.differences += 1;
                let u = (0..n)
                    .map(|j| (pe[j] - phi[j]) / (eps * sec.s[j]))
                    .collect();
                sg.extra.push((w, u));
            }
        }
        let lr = sur.as_ref().ok_or_else(|| SimError::ShootingFailed {
            iterations: it,
            residual: res,
            why: "no surrogate monodromy".into(),
        })?;
        let b = sys.rhs(&r, &x);
        let mut op = |z: &[f64], out: &mut [f64]| {
            sys.apply(
                &mut |v| {
                    lr.apply(v);
                    Ok(())
                },
                z,
                out,
            )
        };
        let sol = gmres(
            &mut op,
            &b,
            bopts.gmres_tol,
            bopts.restart,
            bopts.max_products,
        )?;
        if !(sol.relative_residual < 1e-3) {
            return Err(SimError::ShootingFailed {
                iterations: it,
                residual: res,
                why: format!(
                    "GMRES on the surrogate reached only {:.2e} relative residual",
                    sol.relative_residual
                ),
            });
        }
        let dx: Vec<f64> = (0..n).map(|j| sol.x[j] * sec.s[j]).collect();
        for j in 0..n {
            x[j] += dx[j];
        }
        t_per *= 1.0 + sol.x[n];
        let largest = (0..n).fold((0, 0.0f64), |m, j| {
            if sol.x[j].abs() > m.1 {
                (j, sol.x[j].abs())
            } else {
                m
            }
        });
        last = Some(Update {
            dx,
            dt: sol.x[n],
            halvings: 0,
            largest,
        });
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moved_matches_nearest_values() {
        let a = [(1.0, 0.0), (0.1, 0.2), (0.1, -0.2)];
        let swapped = [(1.0, 0.0), (0.1, -0.2), (0.1, 0.2)];
        assert_eq!(moved_from(&a, &swapped), 0.0);
        assert!(moved_from(&a, &[]).is_infinite());
        let shifted = [(1.0 + 4e-9, 0.0), (0.1, 0.2), (0.1, -0.2)];
        assert!((moved_from(&shifted, &a) - 4e-9).abs() < 1e-15);
    }

    #[test]
    fn the_surrogate_is_exact_on_its_space_and_its_extra_directions() {
        // A = diag(0.5, 0.25, 0, 0) plus a coupling of e4 into e1: the space of e1 and e2
        // misses it, the extra direction e4 carries it
        let n = 4;
        let a = |v: &[f64]| vec![0.5 * v[0] + 2.0 * v[3], 0.25 * v[1], 0.0, 0.0];
        let start = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0];
        let mut ba = BlockArnoldi::new(n, &start, 2).unwrap();
        ba.sweep(&mut |x: &mut [f64], k: usize| {
            for col in x.chunks_exact_mut(n).take(k) {
                let y = a(col);
                col.copy_from_slice(&y);
            }
            Ok(())
        })
        .unwrap();
        let mut sg = Surrogate {
            ba,
            extra: Vec::new(),
        };
        let r = [0.3, -0.2, 0.0, 0.7];
        let w = sg.new_direction(&r).expect("e4 is new");
        assert!((w[3] - 1.0).abs() < 1e-15 && w[..3].iter().all(|x| x.abs() < 1e-15));
        sg.extra.push((w.clone(), a(&w)));
        assert!(sg.new_direction(&r).is_none(), "nothing new left");
        let mut v = r.to_vec();
        sg.apply(&mut v);
        let want = a(&r);
        for (g, w) in v.iter().zip(&want) {
            assert!((g - w).abs() < 1e-15, "{v:?} vs {want:?}");
        }
    }
}
