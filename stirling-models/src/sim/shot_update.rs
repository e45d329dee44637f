//! A Newton update of the block route's shot, kept so that it can be taken back: the return
//! map from the updated start, and halvings of the update when that run fails.

use stirling_dsl::Model;

use super::integrate::SolverStats;
use super::monodromy::run_recorded;
use super::shooting::ShootingOptions;
use super::SimError;

/// A Newton update of the start `x` and the period, kept so that it can be taken back.
pub(super) struct Update {
    pub dx: Vec<f64>,
    pub dt: f64,
    pub halvings: usize,
    /// The state the full update moved most, and by how much (in its scale).
    pub largest: (usize, f64),
}

/// Halvings of a Newton update whose return map fails before the shot gives up.
pub(super) const MAX_HALVINGS: usize = 6;

/// The return map from `x` over `t_per`; when the run fails after a Newton update (`last`),
/// half of that update is taken back and the run tried again, up to [`MAX_HALVINGS`] times.
/// Why: the surrogate's Newton step is exact only on the surrogate's space, so a full step
/// can overshoot. It did not help the one failure seen (n = 10,000, docs/performance.md):
/// there the update moved no state by more than 2.6e-4 of its scale and the BDF still could
/// not take its first step from it, so the error names the state the update moved most.
pub(super) fn run_from_update(
    model: &dyn Model,
    p: &[f64],
    (x, t_per): (&mut Vec<f64>, &mut f64),
    opts: &ShootingOptions,
    mut last: Option<&mut Update>,
) -> Result<(Vec<f64>, SolverStats), SimError> {
    loop {
        let err = match run_recorded(model, p, x, *t_per, &opts.sim, &mut |_, _, _| Ok(())) {
            Ok(v) => return Ok(v),
            Err(e) => e,
        };
        let Some(u) = last.as_deref_mut().filter(|u| u.halvings < MAX_HALVINGS) else {
            return Err(err);
        };
        for (xj, dj) in x.iter_mut().zip(u.dx.iter_mut()) {
            *dj *= 0.5;
            *xj -= *dj;
        }
        *t_per /= 1.0 + u.dt;
        u.dt *= 0.5;
        *t_per *= 1.0 + u.dt;
        u.halvings += 1;
    }
}
