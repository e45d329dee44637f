//! A limit cycle asked of an engine that is stable at rest: there is none, so the settling
//! run either finds no periodic motion ("run longer" would not help) or the shooting closes
//! on the rest state itself (a "cycle" of zero amplitude, exit 0). Both are said as what they
//! are: the engine does not run at these parameters.

use anyhow::bail;
use stirling_dsl::Model;
use stirling_models::linear::{dynamic_poles, NewtonOptions};
use stirling_models::sim::LimitCycleReport;

/// Largest distance of the multiplier nearest 1 from 1 on a periodic orbit (a limit cycle of
/// an autonomous engine has a Floquet multiplier at 1).
const TRIVIAL_TOLERANCE: f64 = 0.05;
/// Position amplitude below which the orbit is the rest state (m).
const REST_AMPLITUDE: f64 = 1e-9;

/// The rightmost pole at rest when every pole lies in the left half plane (`None`: unstable
/// at rest, or the rest state cannot be linearized).
pub fn stable_at_rest(model: &dyn Model, p: &[f64]) -> Option<f64> {
    let d = dynamic_poles(model, p, &NewtonOptions::default()).ok()?;
    let right = d
        .poles
        .iter()
        .map(|q| q.re)
        .fold(f64::NEG_INFINITY, f64::max);
    (right < 0.0).then_some(right)
}

/// Why there is no cycle, for an engine stable at rest (its rightmost pole `re`).
pub fn no_cycle(re: f64) -> String {
    format!(
        "the engine is stable at rest at these parameters (every pole at rest in the left half \
         plane, the rightmost at {re:.4} 1/s): a start-up decays to rest and there is no limit \
         cycle to find, however long the run; `stirling linearize` shows the poles, and a larger \
         temperature ratio (Th/Tk) or less damping makes the engine run"
    )
}

/// Refuse a "limit cycle" that is the rest state of an engine stable at rest.
pub fn check_cycle(model: &dyn Model, p: &[f64], lc: &LimitCycleReport) -> anyhow::Result<()> {
    let Some(re) = stable_at_rest(model, p) else {
        return Ok(());
    };
    let off_one =
        !lc.cycle.floquet.is_empty() && lc.cycle.trivial_multiplier_error() > TRIVIAL_TOLERANCE;
    let still = lc.figures.x_amp.max(lc.figures.y_amp) < REST_AMPLITUDE;
    if off_one || still {
        bail!(
            "no limit cycle: the orbit found is the rest state (position amplitudes {:.3e} m, \
             {:.3e} m; no Floquet multiplier at 1): {}",
            lc.figures.x_amp,
            lc.figures.y_amp,
            no_cycle(re)
        );
    }
    Ok(())
}
