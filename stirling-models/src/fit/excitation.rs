//! Whether a record can carry a fit: every measured channel must move well above its noise
//! on the training block, and the block must hold at least two cycles. A start-up record
//! that begins near rest and grows passes (its motion over the block is large); a record
//! without motion, or shorter than a couple of cycles, is refused with the reason.

use super::FitError;
use crate::data::Measured;
use crate::signal::{cycle_frequency, noise_sigma};

/// Least samples per cycle of the recorded motion: below it the record cannot follow the
/// cycle, and a record sampled below twice the engine's frequency shows an alias of the motion
/// (a 13.4 Hz engine sampled at 1 Hz shows a 0.4 Hz oscillation of 2.5 samples per cycle,
/// which a fit took for a soft spring: kd 55.8 against 650.7).
pub const MIN_SAMPLES_PER_CYCLE: f64 = 10.0;

/// Least ratio of a channel's standard deviation to its noise level on the training block.
pub const MIN_SIGNAL_TO_NOISE: f64 = 5.0;

/// Refuse the training block `tr` (inclusive sample indices) of `data` if it cannot carry a
/// fit (interval `dt`).
pub fn check(data: &Measured, tr: (usize, usize), dt: f64) -> Result<(), FitError> {
    for ch in ["p", "p_hot", "x", "y"] {
        let Some(v) = data.channel(ch) else { continue };
        let seg = &v[tr.0..=tr.1];
        let n = seg.len() as f64;
        let mean = seg.iter().sum::<f64>() / n;
        let sd = (seg.iter().map(|a| (a - mean) * (a - mean)).sum::<f64>() / n).sqrt();
        let noise = noise_sigma(seg);
        if !(sd > 0.0 && sd > MIN_SIGNAL_TO_NOISE * noise) {
            return Err(FitError::NoExcitation {
                file: data.source.clone(),
                channel: ch.into(),
                sd,
                noise,
            });
        }
    }
    let cycles = ["x", "y", "p"]
        .iter()
        .filter_map(|c| data.channel(c))
        .find_map(|v| cycle_frequency(&v[tr.0..=tr.1], dt));
    let Some(freq) = cycles else {
        return Err(FitError::TooFewCycles {
            file: data.source.clone(),
            seconds: (tr.1 - tr.0) as f64 * dt,
        });
    };
    let per_cycle = 1.0 / (freq * dt);
    if per_cycle < MIN_SAMPLES_PER_CYCLE {
        return Err(FitError::Undersampled {
            file: data.source.clone(),
            rate: 1.0 / dt,
            freq,
            per_cycle,
        });
    }
    Ok(())
}
