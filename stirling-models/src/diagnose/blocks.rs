//! The training and held-out blocks of a record.

use super::{DiagnoseError, DiagnoseOptions};
use crate::data::Measured;
use crate::signal::{cycle_frequency, noise_sigma};

/// The held-out motion must exceed the noise by this factor (rms of the mean-removed signal
/// against the noise's standard deviation): below it the crossings are the noise's.
const MOTION_OVER_NOISE: f64 = 5.0;

/// Training and held-out blocks (times and sample ranges) of a record.
pub(super) struct Blocks {
    pub train: (f64, f64),
    pub holdout: (f64, f64),
    pub train_idx: (usize, usize),
    pub hold_idx: (usize, usize),
}

pub(super) fn blocks(data: &Measured, opts: &DiagnoseOptions) -> Result<Blocks, DiagnoseError> {
    if data.t.len() < 100 {
        return Err(DiagnoseError::TooFewSamples {
            file: data.source.clone(),
            samples: data.t.len(),
            need: 100,
        });
    }
    let t0 = data.t[0];
    let t1 = data.t[data.t.len() - 1];
    let train = opts.train.unwrap_or((t0, t0 + 0.6 * (t1 - t0)));
    let holdout = opts.holdout.unwrap_or((train.1, t1));
    if holdout.0 < train.1 - 1e-12 {
        return Err(DiagnoseError::BlockOrder { train, holdout });
    }
    let dt = data.dt();
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(data.t.len() - 1);
    let burn = (opts.fit.burn_in / dt).round() as usize;
    let train_idx = ((idx(train.0) + burn).min(idx(train.1)), idx(train.1));
    let hold_idx = (idx(holdout.0).max(train_idx.1), idx(holdout.1) + 1);
    if train_idx.1 < train_idx.0 + 50 || hold_idx.1 < hold_idx.0 + 50 {
        return Err(DiagnoseError::ShortRecord {
            file: data.source.clone(),
            seconds: t1 - t0,
            burn_in: opts.fit.burn_in,
            need: 50,
        });
    }
    let motion = match (&data.x, &data.p) {
        (Some(x), _) => Some(("x", x)),
        (None, Some(p)) => Some(("p", p)),
        _ => None,
    };
    if let Some((channel, v)) = motion {
        let held = &v[hold_idx.0..hold_idx.1];
        if cycle_frequency(held, dt).is_none() {
            return Err(DiagnoseError::HoldoutCycles {
                file: data.source.clone(),
                from: holdout.0,
                to: holdout.1,
            });
        }
        // crossings of the noise count as cycles: the motion must stand above it too
        check_motion(data, channel, held, holdout)?;
    }
    Ok(Blocks {
        train,
        holdout,
        train_idx,
        hold_idx,
    })
}

/// Refuse a held-out block whose motion is buried in the noise (an engine that stopped).
fn check_motion(
    data: &Measured,
    channel: &'static str,
    held: &[f64],
    holdout: (f64, f64),
) -> Result<(), DiagnoseError> {
    let mean = held.iter().sum::<f64>() / held.len() as f64;
    let rms = (held.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / held.len() as f64).sqrt();
    let noise = noise_sigma(held);
    if rms > MOTION_OVER_NOISE * noise {
        return Ok(());
    }
    Err(DiagnoseError::NoMotion {
        file: data.source.clone(),
        from: holdout.0,
        to: holdout.1,
        channel,
        rms,
        noise,
        need: MOTION_OVER_NOISE,
    })
}
