//! The record's cycle against the model's before any fitting: a record sampled so slowly
//! that the motion aliases also looks still and noisy, and the fit's first check (does every
//! channel move above its noise?) would blame the engine ("is it running?") instead of the
//! sampling. The frequency check is run first here, on the training block the fit will use.

use stirling_dsl::Model;
use stirling_models::data::Measured;
use stirling_models::fit::excitation::check_model_frequency;

use super::blocks::Block;

/// Refuse a record whose cycle on the training block (`train`, or the first `default_train`
/// fraction) is far from the model's own at `p`: aliased, in another time unit, another
/// engine. A block too short to judge is left to the fit's own checks.
pub fn check_sampling(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    train: Block,
    default_train: f64,
) -> anyhow::Result<()> {
    let n = data.t.len();
    let dt = data.dt();
    if n < 2 || !(dt > 0.0) {
        return Ok(());
    }
    let (t0, t1) = (data.t[0], data.t[n - 1]);
    let (a, b) = train.unwrap_or((t0, t0 + default_train * (t1 - t0)));
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(n - 1);
    let tr = (idx(a), idx(b));
    if tr.1 < tr.0 + 10 {
        return Ok(());
    }
    check_model_frequency(model, p, data, tr, dt)?;
    Ok(())
}
