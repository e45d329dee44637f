//! **Where**: the residuals of the calibrated nominal model (driven subsystems, no phase
//! drift) per channel, per harmonic of the cycle (DFT over whole cycles), per phase of the
//! cycle (binned), per subsystem (stage-1 mechanics driven by measured pressure vs stage-2
//! gas driven by measured displacements); and limit-cycle features (frequency, amplitudes,
//! phase angle, growth rate, cycle work) of the measured record against a free run of the
//! calibrated model from the measured initial positions and velocities, where pointwise
//! comparison is dominated by phase drift.

use serde::Serialize;
use stirling_dsl::{Model, StateKind};

use super::context::{Context, Eval};
use super::DiagnoseError;
use crate::data::{cycle_mean, Measured};
use crate::signal::cycle_starts;
use crate::signal::dft;
use crate::signal::savitzky_golay;
use crate::sim::{simulate, SimOptions};

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

/// Limit-cycle features of a record.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CycleFeatures {
    pub frequency_hz: f64,
    pub x_amp: f64,
    pub y_amp: f64,
    pub p_amp: f64,
    /// Phase by which the displacer leads the piston (deg), fundamental.
    pub phase_x_y_deg: f64,
    /// Growth rate of the displacer amplitude (1/s).
    pub growth_rate: f64,
    /// Gas work per cycle, `oint p dV` with `dV = -(Ar dx + (A - Ar) dy)` (J).
    pub cycle_work: f64,
}

/// Measured vs free-run features.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Features {
    pub measured: CycleFeatures,
    pub free_run: Option<CycleFeatures>,
    pub note: Option<String>,
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
    pub features: Features,
}

/// Features of `x`, `y`, `p` (already on a common grid) between cycle starts.
pub fn features(
    x: &[f64],
    y: &[f64],
    p: &[f64],
    dt: f64,
    starts: &[usize],
    a: f64,
    ar: f64,
) -> CycleFeatures {
    if starts.len() < 2 {
        return CycleFeatures::default();
    }
    let (i0, i1) = (starts[0], starts[starts.len() - 1]);
    let ncyc = (starts.len() - 1) as f64;
    let per = (i1 - i0) as f64 / ncyc;
    let fund = |v: &[f64]| dft(&v[i0..i1], per, 1);
    let (xr, xi) = fund(x);
    let (yr, yi) = fund(y);
    let (pr, pi) = fund(p);
    let mut phase = (xi.atan2(xr) - yi.atan2(yr)).to_degrees();
    while phase > 180.0 {
        phase -= 360.0;
    }
    while phase < -180.0 {
        phase += 360.0;
    }
    // per-cycle amplitude of x: half the peak-to-peak; growth rate by regression on its log
    let (mut st, mut sl, mut stt, mut stl, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut work = 0.0;
    for w in starts.windows(2) {
        let seg = &x[w[0]..w[1]];
        let amp = 0.5
            * (seg.iter().cloned().fold(f64::MIN, f64::max)
                - seg.iter().cloned().fold(f64::MAX, f64::min));
        let t = 0.5 * (w[0] + w[1]) as f64 * dt;
        if amp > 0.0 {
            let l = amp.ln();
            st += t;
            sl += l;
            stt += t * t;
            stl += t * l;
            n += 1.0;
        }
        for i in w[0]..w[1] {
            let dv = -(ar * (x[i + 1] - x[i]) + (a - ar) * (y[i + 1] - y[i]));
            work += 0.5 * (p[i] + p[i + 1]) * dv;
        }
    }
    let growth = if n > 1.0 {
        (n * stl - st * sl) / (n * stt - st * st)
    } else {
        f64::NAN
    };
    CycleFeatures {
        frequency_hz: 1.0 / (per * dt),
        x_amp: xr.hypot(xi),
        y_amp: yr.hypot(yi),
        p_amp: pr.hypot(pi),
        phase_x_y_deg: phase,
        growth_rate: growth,
        cycle_work: work / ncyc,
    }
}

fn free_run(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    first: usize,
    last: usize,
    a: f64,
    ar: f64,
) -> Result<CycleFeatures, DiagnoseError> {
    let (Some(xm), Some(ym)) = (data.x.as_ref(), data.y.as_ref()) else {
        return Err(DiagnoseError::NeedsPositions {
            stage: "the localization's free run",
        });
    };
    let dt = data.dt();
    let (sx, vx) = savitzky_golay(xm, dt, 6, 4);
    let (sy, vy) = savitzky_golay(ym, dt, 6, 4);
    let (mx, my) = (cycle_mean(xm), cycle_mean(ym));
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    let mut pos = 0;
    let mut vel = 0;
    for (i, s) in model.states().iter().enumerate() {
        match s.kind {
            StateKind::Position(_) => {
                x0[i] = if pos == 0 {
                    sx[first] - mx
                } else {
                    sy[first] - my
                };
                pos += 1;
            }
            StateKind::Velocity(_) => {
                x0[i] = if vel == 0 { vx[first] } else { vy[first] };
                vel += 1;
            }
            _ => {}
        }
    }
    let samples: Vec<f64> = (0..=last - first).map(|k| k as f64 * dt).collect();
    let tr = simulate(
        model,
        p,
        &x0,
        samples[samples.len() - 1],
        &samples,
        &SimOptions::default(),
    )
    .map_err(|source| DiagnoseError::Sim {
        stage: "the localization's free run",
        source,
    })?;
    let ps = crate::layout::StateLayout::of(model).pressures;
    let ic = *ps.last().ok_or_else(|| DiagnoseError::NoPressure {
        model: model.name().into(),
    })?;
    let col = |i: usize| tr.x.iter().map(|r| r[i]).collect::<Vec<f64>>();
    let (x, y, pc) = (col(0), col(2), col(ic));
    // the free run keeps its own phase: its own crossings over the same span
    let m = Measured {
        source: String::new(),
        t: samples.clone(),
        p: Some(pc.clone()),
        p_hot: None,
        x: Some(x.clone()),
        y: Some(y.clone()),
    };
    let own = cycle_starts(&m, (0, x.len()));
    Ok(features(&x, &y, &pc, dt, &own, a, ar))
}

/// Localize the gap of the calibrated nominal model.
pub fn localize(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    nominal: &Eval,
    prof: &Context,
) -> Localization {
    let dt = data.dt();
    let first = prof.train_idx.0;
    let last = prof.hold_idx.1;
    let starts = cycle_starts(data, (first, last));
    let period = if starts.len() >= 2 {
        (starts[starts.len() - 1] - starts[0]) as f64 / (starts.len() - 1) as f64 * dt
    } else {
        f64::NAN
    };
    let mut channels = Vec::new();
    let (mut mech, mut nm, mut gas, mut ng) = (0.0, 0, 0.0, 0);
    let mut dominant_harmonic = Vec::new();
    for (c, r) in nominal.channels.iter().zip(&nominal.hp) {
        let s = prof.noise_of(c);
        let ms = |a: usize, b: usize| {
            r[a..b].iter().map(|v| (v / s).powi(2)).sum::<f64>() / (b - a).max(1) as f64
        };
        let (tr, ho) = (
            ms(prof.train_idx.0, prof.train_idx.1),
            ms(prof.hold_idx.0, prof.hold_idx.1),
        );
        let sub = if c == "x" || c == "y" {
            "mechanics"
        } else {
            "gas"
        };
        if sub == "mechanics" {
            mech += ho;
            nm += 1;
        } else {
            gas += ho;
            ng += 1;
        }
        let (mut harmonics, mut hnoise, mut bins) = (
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
            hnoise = 2.0 * s / (seg.len() as f64).sqrt();
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
            bins = acc
                .iter()
                .map(|(a, n)| (a / (*n).max(1) as f64).sqrt())
                .collect();
            let k = (1..HARMONICS)
                .max_by(|&a, &b| harmonics[a].total_cmp(&harmonics[b]))
                .unwrap_or(1);
            dominant_harmonic.push((c.clone(), k));
        }
        channels.push(ChannelLoc {
            channel: c.clone(),
            subsystem: sub.into(),
            train_ratio: tr.sqrt(),
            holdout_ratio: ho.sqrt(),
            harmonics,
            harmonic_noise: hnoise,
            phase_bins: bins,
        });
    }
    let mechanics_error = if nm > 0 { mech / nm as f64 } else { f64::NAN };
    let gas_error = if ng > 0 { gas / ng as f64 } else { f64::NAN };
    let dominant_subsystem = if (mechanics_error - 1.0) >= (gas_error - 1.0) {
        "mechanics"
    } else {
        "gas"
    }
    .to_string();
    let a = model.param_index("A").map(|i| p[i]).unwrap_or(0.0);
    let ar = model.param_index("Ar").map(|i| p[i]).unwrap_or(0.0);
    let mut features_out = Features::default();
    if let (Some(x), Some(y), Some(pm)) = (data.x.as_ref(), data.y.as_ref(), data.p.as_ref()) {
        features_out.measured = features(x, y, pm, dt, &starts, a, ar);
        match free_run(model, p, data, first, last.saturating_sub(1), a, ar) {
            Ok(f) => features_out.free_run = Some(f),
            Err(e) => features_out.note = Some(format!("free run failed: {e}")),
        }
    }
    Localization {
        channels,
        mechanics_error,
        gas_error,
        dominant_subsystem,
        dominant_harmonic,
        period,
        cycles: starts.len().saturating_sub(1),
        features: features_out,
    }
}
