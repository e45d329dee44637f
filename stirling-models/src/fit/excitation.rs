//! Whether a record can carry a fit: every measured channel must move well above its noise
//! on the training block, and the block must hold at least two cycles. A start-up record
//! that begins near rest and grows passes (its motion over the block is large); a record
//! without motion, or shorter than a couple of cycles, is refused with the reason.

use stirling_dsl::Model;

use super::FitError;
use crate::data::Measured;
use crate::linear::dynamics::dynamic_poles;
use crate::linear::equilibrium::NewtonOptions;
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
    check_motion(data, tr)?;
    let Some(freq) = record_frequency(data, tr, dt) else {
        return Err(FitError::TooFewCycles {
            file: data.source.clone(),
            seconds: (tr.1 - tr.0) as f64 * dt,
        });
    };
    check_rate(data, freq, dt)
}

/// Every measured channel moves well above its noise on the training block `tr` (a still
/// engine, or a record of noise, has no cycle to fit).
pub fn check_motion(data: &Measured, tr: (usize, usize)) -> Result<(), FitError> {
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
    Ok(())
}

/// The record's cycle frequency on the training block `tr`, when it has one.
pub fn record_frequency(data: &Measured, tr: (usize, usize), dt: f64) -> Option<f64> {
    ["x", "y", "p"]
        .iter()
        .filter_map(|c| data.channel(c))
        .find_map(|v| cycle_frequency(&v[tr.0..=tr.1], dt))
}

/// Most the record's cycle frequency may differ from the model's (a factor either way): a
/// factor 4 is a 16-fold spring, beyond what a start from the declared parameters reaches;
/// a record in milliseconds moves 1000 times too slow, an aliased one too slow as well.
pub const MAX_FREQUENCY_RATIO: f64 = 4.0;

/// Refuse a record whose cycle is far from the model's own frequency at `p` (its dominant
/// oscillatory pole at rest): a time column in the wrong unit, an aliased or resampled record,
/// or another engine. Models without an oscillatory pole (or whose rest state cannot be
/// linearized) are not checked here.
pub fn check_model_frequency(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    tr: (usize, usize),
    dt: f64,
) -> Result<(), FitError> {
    let Some(rec) = record_frequency(data, tr, dt) else {
        return Ok(());
    };
    let Some(f_model) = model_frequency(model, p) else {
        return Ok(());
    };
    // a record that does not move above its noise, sampled fast enough for the model's
    // cycle, is a still engine (or noise), which [`check`] names; sampled too slowly, its
    // samples are an alias of the motion (they look like noise to the motion check)
    if check_motion(data, tr).is_err() && dt * f_model * MIN_SAMPLES_PER_CYCLE <= 1.0 {
        return Ok(());
    }
    let ratio = rec / f_model;
    if (1.0 / MAX_FREQUENCY_RATIO..=MAX_FREQUENCY_RATIO).contains(&ratio) {
        return Ok(());
    }
    let hint = if (300.0..3000.0).contains(&(1.0 / ratio)) {
        "the time column looks like milliseconds: give it in seconds"
    } else if (300.0..3000.0).contains(&ratio) {
        "the time column looks like kiloseconds or the record was decimated: give time in seconds"
    } else if ratio < 1.0 {
        "a record sampled too slowly shows an alias of the motion (check the rate against the engine's frequency), or the time column's unit is wrong"
    } else {
        "check the time column's unit, or start the fit nearer the engine (--set, --params)"
    };
    Err(FitError::FrequencyMismatch {
        file: data.source.clone(),
        record: rec,
        model: f_model,
        hint: hint.into(),
    })
}

/// The model's own cycle frequency at `p` (Hz): its dominant oscillatory pole at rest. A
/// kinematic engine has none to compare: it cycles at its flywheel's speed, which its rest
/// state does not set (the gamma LTD's pole at rest is 0.39 Hz, its running speed 2.8 Hz;
/// its fit checks the measured angle's speed against the record's cycle instead).
fn model_frequency(model: &dyn Model, p: &[f64]) -> Option<f64> {
    if !crate::layout::StateLayout::flywheels(model).is_empty() {
        return None;
    }
    let d = dynamic_poles(model, p, &NewtonOptions::default()).ok()?;
    d.poles
        .iter()
        .filter(|q| q.im > 0.0)
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .map(|q| q.freq_hz)
}

fn check_rate(data: &Measured, freq: f64, dt: f64) -> Result<(), FitError> {
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
