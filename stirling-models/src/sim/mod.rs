//! Nonlinear simulation: the stiff integrator on the analytic Jacobian, limit
//! cycles by shooting, Floquet multipliers, and cycle work.
//!
//! - [`integrate`](mod@crate::sim::integrate): BDF step loop (diffsol), samples, crossings,
//!   nonphysical checks.
//! - [`block_lu`](crate::sim::block_lu): the linear solver of repeated-block Newton matrices
//!   (sensitivity systems).
//! - [`system`](crate::sim::system): the model, energy-quadrature and variational systems.
//! - [`cycle`](crate::sim::cycle): periodicity from upward crossings of the piston position;
//!   amplitudes, phase.
//! - [`shooting`](crate::sim::shooting): Newton on the return map, monodromy matrix, Floquet
//!   multipliers.
//! - [`work`](crate::sim::work): `closed-integral P dV` per vessel, indicated power.
//!
//! [`limit_cycle`](crate::sim::limit_cycle) chains them: settle from a perturbed state, shoot,
//! measure. Up to [`SHOOTING_MAX_STATES`](crate::sim::SHOOTING_MAX_STATES) states it shoots with
//! the dense monodromy, above by the block route (Newton on a low-rank surrogate of the
//! monodromy, the leading Floquet multipliers by block Arnoldi, memory linear in the states);
//! [`limit_cycle_with`](crate::sim::limit_cycle_with) chooses, and can force the Newton-Krylov
//! route (stored stage factors, single-vector products) or no shooting.
//!
//! - [`monodromy`](crate::sim::monodromy): the monodromy by Radau IIA along the BDF trajectory.
//! - [`tangent`](crate::sim::tangent): monodromy-vector products along a recorded BDF trajectory.
//! - [`krylov_shooting`](crate::sim::krylov_shooting), [`gmres`](crate::sim::gmres),
//!   [`floquet_arnoldi`](crate::sim::floquet_arnoldi): the matrix-free route.
//! - [`block_shooting`](crate::sim::block_shooting), [`block_arnoldi`](crate::sim::block_arnoldi),
//!   [`tangent_sweep`](crate::sim::tangent_sweep): the block route.

mod adapter;
/// Block Arnoldi on an operator applied to blocks of vectors.
pub mod block_arnoldi;
/// A linear solver for block-diagonal Newton matrices whose blocks repeat.
pub mod block_lu;
/// Block shooting (large cycles, memory linear in the states).
pub mod block_shooting;
/// Periodic motion: settling, the cycle figures.
pub mod cycle;
/// Dense-output helpers of the step loop (crossings, step hook, error mapping).
mod dense_output;
/// Leading Floquet multipliers by Arnoldi on monodromy-vector products.
pub mod floquet_arnoldi;
/// Restarted GMRES on a matrix-free operator.
pub mod gmres;
/// The indicated work of a sampled p-V record (a kinematic engine's volume at its angle).
pub mod indicated;
/// The step loop.
pub mod integrate;
/// A process-wide request to stop the simulations in progress (Ctrl-C in an interactive
/// front end).
pub mod interrupt;
/// Newton-Krylov shooting (large cycles).
pub mod krylov_shooting;
/// A dense LU solving many right-hand-side lanes at once (the sensitivity columns).
pub mod lane_lu;
/// The monodromy matrix without the `n (n + 1)`-state variational system.
pub mod monodromy;
/// The nonphysical-state check run after every accepted step.
pub mod physical;
/// A sparse LU that keeps its pivots between factorizations (KLU's refactorization).
pub mod refactor_lu;
/// A kinematic engine as it runs: speed, indicated work, the gas's cycle means.
pub mod running;
/// Schmidt's isothermal analysis of a kinematic engine on its own volumes.
pub mod schmidt;
/// Forward sensitivities by the staggered corrector (diffsol's sensitivity BDF).
pub mod sens;
/// Limit cycles by single shooting.
pub mod shooting;
/// A Newton update of the block route's shot, and its halvings.
mod shot_update;
/// The Radau stage matrix assembled by precomputed positions.
mod stage_slots;
/// The ODE systems the integrator runs.
pub mod system;
/// Monodromy-vector products without the monodromy matrix.
pub mod tangent;
/// Block products with the stage matrices factored on several threads.
pub mod tangent_sweep;
/// Cycle work.
pub mod work;

use serde::Serialize;
use stirling_dsl::Model;

pub use block_shooting::{shoot_block, shoot_block_counted, BlockCounts, BlockOptions};
pub use cycle::{figures, periodic, settle, CycleFigures, Settled};
pub use floquet_arnoldi::ArnoldiOptions;
pub use integrate::{
    check_physical, integrate, simulate, uniform_samples, Crossing, Hooks, LinearSolverKind,
    SimOptions, SolverStats, Trajectory, SPARSE_THRESHOLD,
};
pub use krylov_shooting::{shoot_krylov, shoot_krylov_counted, KrylovCounts, KrylovOptions};
pub use physical::PhysicalCheck;
pub use sens::{integrate_sens, SensSystem};
pub use shooting::{
    floquet_multipliers, floquet_multipliers_scaled, flow_with_monodromy, flow_with_monodromy_by,
    shoot, LimitCycle, MonodromyMethod, ShootingOptions,
};
pub use system::{state_scale, EnergySystem, ModelSystem, OdeSystem, VariationalSystem};
pub use work::{cycle_work, indicated_power, CycleWork};

/// Why a simulation stopped short.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimError {
    #[error("nonphysical state at t = {t:.6e} s: {quantity} = {value:.6e}")]
    Nonphysical {
        t: f64,
        quantity: String,
        value: f64,
    },
    #[error("step size collapsed below the minimum at t = {t:.6e} s (the solution is singular or leaves the physical range there)")]
    StepSizeCollapse { t: f64 },
    #[error("solver failure at t = {t:.6e} s: {why}")]
    SolverFailure { t: f64, why: String },
    #[error("step limit of {max_steps} reached at t = {t:.6e} s")]
    TooManySteps { t: f64, max_steps: usize },
    #[error("initial state has {found} entries; the model has {expected} states")]
    DimensionMismatch { expected: usize, found: usize },
    #[error("no periodic motion by t = {t:.4} s ({crossings} upward piston crossings); run longer or start closer to the cycle")]
    NotPeriodic { t: f64, crossings: usize },
    #[error("shooting failed after {iterations} Newton iterations (scaled residual {residual:.3e}): {why}")]
    ShootingFailed {
        iterations: usize,
        residual: f64,
        why: String,
    },
    #[error("the leading Floquet multipliers did not settle in {products} Arnoldi steps (last change {change:.2e})")]
    FloquetNotConverged { products: usize, change: f64 },
    #[error("{0}")]
    BadOption(String),
    #[error("interrupted at t = {t:.6e} s (a stop was requested)")]
    Interrupted { t: f64 },
}

/// A limit cycle with its figures.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitCycleReport {
    pub settled: Settled,
    pub cycle: LimitCycle,
    pub figures: CycleFigures,
    pub work: CycleWork,
    /// Uniform samples over one period of the converged orbit (last = first).
    pub orbit: Vec<Vec<f64>>,
    /// Counters of the settling run, the shooting and the orbit run together.
    pub stats: SolverStats,
    /// How the cycle was refined.
    pub route: ShootingRoute,
}

/// Above this many states [`Shooting::Auto`] shoots by the block route instead of the
/// dense monodromy: that is dense `n x n` and each Radau step solves for all `n` columns
/// (nsection n = 100, 208 states: about 16 s for the whole `limit_cycle` in release;
/// n = 1000 would take hours). The block route has no upper limit: nsection n = 1000 shoots
/// in about 12 s and 0.2 GB, n = 10,000 in minutes (docs/performance.md, issue 37).
pub const SHOOTING_MAX_STATES: usize = 400;

/// Whether and how [`limit_cycle_with`] refines the settled cycle by shooting (and so
/// reports Floquet multipliers).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shooting {
    /// Dense up to [`SHOOTING_MAX_STATES`] states, the block route above.
    #[default]
    Auto,
    /// The same as `Auto` (which shoots at every size since the block route).
    Always,
    /// The dense monodromy route at any size (all multipliers).
    Dense,
    /// The Newton-Krylov route at any size (the leading multipliers; stage factors kept).
    Krylov,
    /// The block route at any size (the leading multipliers; nothing kept).
    Block,
    /// Measure the cycle from the last simulated period (no Floquet multipliers).
    Never,
}

/// The route [`limit_cycle_with`] took.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ShootingRoute {
    /// Gauss-Newton on the dense monodromy; all Floquet multipliers.
    #[default]
    Dense,
    /// Newton-Krylov on monodromy-vector products; the leading multipliers by Arnoldi.
    Krylov,
    /// Newton on a low-rank surrogate of the monodromy; the leading multipliers by block
    /// Arnoldi on block products.
    Block,
    /// No shooting: the settled cycle as measured.
    Settled,
}

impl Shooting {
    /// The route for a model of `n_states` states.
    pub fn route(self, n_states: usize) -> ShootingRoute {
        let by_size = if n_states <= SHOOTING_MAX_STATES {
            ShootingRoute::Dense
        } else {
            ShootingRoute::Block
        };
        match self {
            Shooting::Auto | Shooting::Always => by_size,
            Shooting::Dense => ShootingRoute::Dense,
            Shooting::Krylov => ShootingRoute::Krylov,
            Shooting::Block => ShootingRoute::Block,
            Shooting::Never => ShootingRoute::Settled,
        }
    }
}

/// Settle from `x0` (at most `t_max`), refine by shooting, and measure the cycle.
pub fn limit_cycle(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    t_max: f64,
    samples: &[f64],
    opts: &SimOptions,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<LimitCycleReport, SimError> {
    limit_cycle_with(model, p, x0, t_max, samples, opts, Shooting::Auto, progress)
}

/// The settled cycle taken as is (no shooting), with its orbit of `n_orbit` samples and the
/// scaled return-map residual of the measured period.
fn settled_cycle(
    model: &dyn Model,
    p: &[f64],
    settled: &Settled,
    n_orbit: usize,
    opts: &SimOptions,
) -> Result<(LimitCycle, Trajectory), SimError> {
    let orbit_t = uniform_samples(settled.period, n_orbit);
    let orbit_run = simulate(model, p, &settled.x0, settled.period, &orbit_t, opts)?;
    let s = state_scale(model, p);
    let residual = orbit_run
        .x_end
        .iter()
        .zip(&settled.x0)
        .zip(&s)
        .map(|((a, b), w)| ((a - b) / w).abs())
        .fold(0.0, f64::max);
    let cycle = LimitCycle {
        x0: settled.x0.clone(),
        period: settled.period,
        monodromy: vec![],
        floquet: vec![],
        iterations: 0,
        residual,
        stats: SolverStats::default(),
    };
    Ok((cycle, orbit_run))
}

/// [`limit_cycle`] with a choice of shooting. Without shooting the cycle is the
/// settled one (periods agreeing to 1e-3), `floquet` and `monodromy` are empty,
/// and `residual` is the scaled return-map residual of the measured period.
pub fn limit_cycle_with(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    t_max: f64,
    samples: &[f64],
    opts: &SimOptions,
    shooting: Shooting,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<LimitCycleReport, SimError> {
    let settled = settle(model, p, x0, t_max, samples, 3, 1e-3, opts, progress)?;
    let route = shooting.route(model.n_states());
    let sh = ShootingOptions {
        sim: SimOptions {
            linear_solver: opts.linear_solver,
            ..ShootingOptions::default().sim
        },
        ..ShootingOptions::default()
    };
    let n_orbit = 512;
    let shot = match route {
        ShootingRoute::Dense => Some(shoot(model, p, &settled.x0, settled.period, &sh)?),
        ShootingRoute::Krylov => Some(shoot_krylov(
            model,
            p,
            &settled.x0,
            settled.period,
            &sh,
            &KrylovOptions::default(),
        )?),
        ShootingRoute::Block => Some(shoot_block(
            model,
            p,
            &settled.x0,
            settled.period,
            &sh,
            &BlockOptions::default(),
        )?),
        ShootingRoute::Settled => None,
    };
    let (cycle, orbit_run) = if let Some(cycle) = shot {
        let orbit_t = uniform_samples(cycle.period, n_orbit);
        let orbit_run = simulate(model, p, &cycle.x0, cycle.period, &orbit_t, &sh.sim)?;
        (cycle, orbit_run)
    } else {
        settled_cycle(model, p, &settled, n_orbit, opts)?
    };
    let fig = figures(model, p, cycle.period, &orbit_run.x);
    let work = cycle_work(model, p, cycle.period, &orbit_run.x);
    let mut stats = settled.trajectory.stats;
    stats.add(&cycle.stats);
    stats.add(&orbit_run.stats);
    Ok(LimitCycleReport {
        settled,
        cycle,
        figures: fig,
        work,
        orbit: orbit_run.x,
        stats,
        route,
    })
}

/// Machine-readable summary of a run (the `--json` of `stirling simulate`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SimSummary {
    pub model: String,
    pub n: usize,
    pub closure: String,
    pub n_states: usize,
    pub t_end: f64,
    pub final_state: Vec<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub frequency_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub x_amp: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub y_amp: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub p_amp: Option<Vec<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work_per_cycle_j: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub work_per_vessel_j: Option<Vec<(String, f64)>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_w: Option<f64>,
    /// Floquet multipliers `[re, im]`, largest modulus first (all of them by the dense
    /// route, the leading ones by the Krylov route).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub floquet: Option<Vec<[f64; 2]>>,
    /// How the limit cycle was refined: `dense`, `krylov` or `settled`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shooting: Option<ShootingRoute>,
    /// A kinematic engine's speed and indicated power over its last whole revolutions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub running: Option<running::Running>,
    /// Schmidt's analysis at the run's cycle-mean gas temperatures and mass.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub schmidt: Option<schmidt::Schmidt>,
    /// Why a kinematic engine's run has no running figures (it did not turn), or no Schmidt.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub running_note: Option<String>,
    pub steps: usize,
    pub rhs_calls: usize,
    pub jacobian_calls: usize,
    pub lu_factorizations: usize,
}

impl SimSummary {
    /// Summary of a plain run.
    pub fn from_run(model: &dyn Model, tr: &Trajectory) -> Self {
        Self {
            model: model.name().to_string(),
            n: model.n(),
            closure: format!("{:?}", model.closure()).to_lowercase(),
            n_states: model.n_states(),
            t_end: tr.t_end,
            final_state: tr.x_end.clone(),
            steps: tr.stats.steps,
            rhs_calls: tr.stats.rhs_calls,
            jacobian_calls: tr.stats.jacobian_calls,
            lu_factorizations: tr.stats.lu_factorizations,
            ..Default::default()
        }
    }

    /// Add the limit-cycle figures (and its counters).
    pub fn with_cycle(mut self, lc: &LimitCycleReport) -> Self {
        let f = &lc.figures;
        self.frequency_hz = Some(f.frequency_hz);
        self.period_s = Some(f.period);
        self.x_amp = Some(f.x_amp);
        self.y_amp = Some(f.y_amp);
        self.p_amp = Some(f.p_amp.clone());
        self.phase_deg = Some(f.phase_deg);
        self.work_per_cycle_j = Some(lc.work.total);
        self.work_per_vessel_j = Some(
            lc.work
                .vessels
                .iter()
                .cloned()
                .zip(lc.work.per_vessel.iter().cloned())
                .collect(),
        );
        self.power_w = Some(indicated_power(lc.work.total, f.frequency_hz));
        self.floquet = (!lc.cycle.floquet.is_empty())
            .then(|| lc.cycle.floquet.iter().map(|&(re, im)| [re, im]).collect());
        self.shooting = Some(lc.route);
        self.steps = lc.stats.steps;
        self.rhs_calls = lc.stats.rhs_calls;
        self.jacobian_calls = lc.stats.jacobian_calls;
        self.lu_factorizations = lc.stats.lu_factorizations;
        self
    }
}

#[cfg(test)]
mod route_tests {
    use super::*;

    /// `auto` by size (nsection n = 10, 400, 1000); the forced routes at any size.
    #[test]
    fn auto_routes_by_size_and_forced_routes_hold() {
        assert_eq!(Shooting::Auto.route(28), ShootingRoute::Dense);
        assert_eq!(Shooting::Auto.route(808), ShootingRoute::Block);
        assert_eq!(Shooting::Auto.route(20008), ShootingRoute::Block);
        assert_eq!(Shooting::Block.route(28), ShootingRoute::Block);
        assert_eq!(Shooting::Krylov.route(2008), ShootingRoute::Krylov);
        assert_eq!(Shooting::Dense.route(808), ShootingRoute::Dense);
        assert_eq!(Shooting::Never.route(28), ShootingRoute::Settled);
    }
}
