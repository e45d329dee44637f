//! **Where**: the residuals of the calibrated nominal model (driven subsystems, no phase drift) per
//! channel, per harmonic of the cycle (DFT over whole cycles), per phase of the cycle (binned), per
//! subsystem (stage-1 mechanics driven by measured pressure vs stage-2 gas driven by measured
//! displacements). The free-running comparison, cycle by cycle, is [`crate::diagnose::sim_gap`].

use serde::Serialize;

use super::context::{Context, Eval};
use crate::data::Measured;
use crate::signal::dft;

/// Number of harmonics reported (0 = mean, 1 = fundamental, ...).
pub const HARMONICS: usize = 6;
/// Number of cycle-phase bins.
pub const PHASE_BINS: usize = 12;

/// Per-channel localization.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelLoc {
    pub channel: String,
    pub subsystem: String,
    /// RMS residual / noise on the training and held-out blocks.
    pub train_ratio: f64,
    pub holdout_ratio: f64,
    /// Residual amplitude per harmonic of the cycle (channel units), `HARMONICS` values.
    pub harmonics: Vec<f64>,
    /// Amplitude white noise alone would give per harmonic, `2 sigma / sqrt(N)`.
    pub harmonic_noise: f64,
    /// RMS residual / noise per phase bin of the cycle (bin 0 starts at the upward
    /// mean crossing of the displacer).
    pub phase_bins: Vec<f64>,
}

/// The localization.
#[derive(Clone, Debug, Serialize)]
pub struct Localization {
    pub channels: Vec<ChannelLoc>,
    /// Held-out mean squared residual / noise variance of each subsystem.
    pub mechanics_error: f64,
    pub gas_error: f64,
    /// `mechanics` or `gas`: the subsystem with the larger excess over the noise floor.
    pub dominant_subsystem: String,
    /// Harmonic with the largest residual amplitude relative to its noise level, per channel.
    pub dominant_harmonic: Vec<(String, usize)>,
    /// Mean cycle period (s) from the displacer's crossings.
    pub period: f64,
    pub cycles: usize,
}

/// Localize the gap of the calibrated nominal model.
pub fn localize(data: &Measured, nominal: &Eval, prof: &Context) -> Localization {
    let dt = data.dt();
    let starts = &prof.starts;
    let period = if starts.len() >= 2 {
        (starts[starts.len() - 1] - starts[0]) as f64 / (starts.len() - 1) as f64 * dt
    } else {
        f64::NAN
    };
    let channels: Vec<ChannelLoc> = nominal
        .channels
        .iter()
        .zip(&nominal.hp)
        .map(|(c, r)| channel_loc(c, r, prof, starts))
        .collect();
    let with_cycles = if starts.len() >= 2 {
        &channels[..]
    } else {
        &[]
    };
    let dominant_harmonic = with_cycles
        .iter()
        .map(|l| {
            let k = (1..HARMONICS)
                .max_by(|&a, &b| l.harmonics[a].total_cmp(&l.harmonics[b]))
                .unwrap_or(1);
            (l.channel.clone(), k)
        })
        .collect();
    let mean_of = |sub: &str| {
        let v: Vec<f64> = channels
            .iter()
            .filter(|l| l.subsystem == sub)
            .map(|l| l.holdout_ratio.powi(2))
            .collect();
        if v.is_empty() {
            f64::NAN
        } else {
            v.iter().sum::<f64>() / v.len() as f64
        }
    };
    let (mechanics_error, gas_error) = (mean_of("mechanics"), mean_of("gas"));
    let dominant_subsystem = if (mechanics_error - 1.0) >= (gas_error - 1.0) {
        "mechanics"
    } else {
        "gas"
    }
    .to_string();
    Localization {
        channels,
        mechanics_error,
        gas_error,
        dominant_subsystem,
        dominant_harmonic,
        period,
        cycles: starts.len().saturating_sub(1),
    }
}

/// The localization of one channel's high-passed residual `r` over the cycles `starts`.
fn channel_loc(c: &str, r: &[f64], prof: &Context, starts: &[usize]) -> ChannelLoc {
    let s = prof.noise_of(c);
    let ms = |(a, b): (usize, usize)| {
        r[a..b].iter().map(|v| (v / s).powi(2)).sum::<f64>() / (b - a).max(1) as f64
    };
    let subsystem = if c == "x" || c == "y" {
        "mechanics"
    } else {
        "gas"
    };
    let (mut harmonics, mut harmonic_noise, mut phase_bins) = (
        vec![f64::NAN; HARMONICS],
        f64::NAN,
        vec![f64::NAN; PHASE_BINS],
    );
    if starts.len() >= 2 {
        let (i0, i1) = (starts[0], starts[starts.len() - 1]);
        let per = (i1 - i0) as f64 / (starts.len() - 1) as f64;
        let seg: Vec<f64> = r[i0..i1]
            .iter()
            .map(|v| if v.is_finite() { *v } else { 0.0 })
            .collect();
        harmonics = (0..HARMONICS)
            .map(|k| {
                let (a, b) = dft(&seg, per, k);
                a.hypot(b)
            })
            .collect();
        harmonic_noise = 2.0 * s / (seg.len() as f64).sqrt();
        phase_bins = phase_rms(r, s, starts);
    }
    ChannelLoc {
        channel: c.into(),
        subsystem: subsystem.into(),
        train_ratio: ms(prof.train_idx).sqrt(),
        holdout_ratio: ms(prof.hold_idx).sqrt(),
        harmonics,
        harmonic_noise,
        phase_bins,
    }
}

/// RMS of `r / s` per phase bin of the cycles `starts`.
fn phase_rms(r: &[f64], s: f64, starts: &[usize]) -> Vec<f64> {
    let mut acc = [(0.0, 0usize); PHASE_BINS];
    for w in starts.windows(2) {
        for i in w[0]..w[1] {
            let ph = (i - w[0]) as f64 / (w[1] - w[0]) as f64;
            let b = ((ph * PHASE_BINS as f64) as usize).min(PHASE_BINS - 1);
            if r[i].is_finite() {
                acc[b].0 += (r[i] / s).powi(2);
                acc[b].1 += 1;
            }
        }
    }
    acc.iter()
        .map(|(a, n)| (a / (*n).max(1) as f64).sqrt())
        .collect()
}
