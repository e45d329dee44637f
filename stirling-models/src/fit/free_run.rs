//! Free-run validation: the identified model simulated on its own (nothing prescribed) from the
//! measured state at the start of a block, compared with the record.
//!
//! The initial state:
//! - positions: the smoothed measured displacements minus the position offsets;
//! - velocities: the derivative of the same Savitzky-Golay smoother the driven stages use;
//! - pressures: the smoothed measured `p` (and `p_hot` when present) minus the pressure offsets;
//!   control volumes between the hot and cold ends get the mix of
//!   [`cold_weight`](crate::fit::static_shift::cold_weight), as in stage 2;
//! - masses (models with mass states): the model's gas inventory (the charge of
//!   `equilibrium_guess`) shared in proportion to `P V / T_rest`, i.e. `m = P V / (R T_rest)`
//!   rescaled so that the total is the charge. Why: the inventory is a parameter of the
//!   identified model (the pressure offsets were estimated against it), so conserving it keeps
//!   the free run's mean pressure consistent with the fit; scaling each mass by its own
//!   `P/P0` instead would add the pressure noise at the start sample to the inventory.
//!
//! Pointwise fit degrades as the self-excited oscillation drifts in phase, so the report also
//! gives the fit over the first cycles only and limit-cycle features (frequency, amplitudes,
//! phases of the fundamental relative to the displacer) of the simulated vs the measured motion.

use std::time::Instant;

use serde::Serialize;
use stirling_dsl::Model;

use super::report::ChannelFit;
use super::{FitError, Series};
use crate::data::Measured;
use crate::signal::{crossing_frequency, fundamental, wrap};
use crate::sim::{simulate, SimOptions, Trajectory};

pub use super::measured_state::{channels, measured_state, Channel, SensorOffsets};
use super::outputs::{outputs, predicted};

/// Fundamental-harmonic features of a periodic motion.
#[derive(Clone, Debug, Serialize)]
pub struct CycleFeatures {
    /// Cycle frequency from the mean crossings of `x` (Hz).
    pub frequency: f64,
    /// `(channel, amplitude of the fundamental)`.
    pub amplitude: Vec<(String, f64)>,
    /// `(channel, phase of the fundamental relative to x)` (rad, in `(-pi, pi]`; positive: leads).
    pub phase: Vec<(String, f64)>,
}

/// Features of channels `(name, samples)` (the first must be `x`); `None` when `x` holds
/// fewer than two cycles.
pub fn cycle_features(series: &[(String, Vec<f64>)], dt: f64) -> Option<CycleFeatures> {
    let f = crossing_frequency(&series[0].1, dt)?;
    let fx: Vec<(f64, f64)> = series.iter().map(|(_, y)| fundamental(y, dt, f)).collect();
    Some(CycleFeatures {
        frequency: f,
        amplitude: series
            .iter()
            .zip(&fx)
            .map(|((n, _), a)| (n.clone(), a.0))
            .collect(),
        phase: series
            .iter()
            .zip(&fx)
            .map(|((n, _), a)| (n.clone(), wrap(a.1 - fx[0].1)))
            .collect(),
    })
}

/// Options of the free run.
#[derive(Clone, Copy, Debug)]
pub struct FreeRunOptions {
    /// Cycles of the short window (fit from the measured state before the phase drifts).
    pub cycles: f64,
    /// Half-width of the smoothing window for the initial state (s).
    pub smooth: f64,
    pub sim: SimOptions,
}

impl Default for FreeRunOptions {
    fn default() -> Self {
        Self {
            cycles: 2.0,
            smooth: 0.006,
            sim: SimOptions {
                rtol: 1e-8,
                atol: 1e-8,
                ..Default::default()
            },
        }
    }
}

/// The free-run validation of a block.
#[derive(Clone, Debug, Serialize)]
pub struct FreeRun {
    /// The block `[a, b]` (s).
    pub block: (f64, f64),
    /// Length of the short window from the block start (s).
    pub short_window: f64,
    /// The initial state from the measurements.
    pub initial_state: Vec<(String, f64)>,
    /// Fit per channel: block `free_run` (the whole block) and `free_run_short` (the first
    /// cycles).
    pub fits: Vec<ChannelFit>,
    pub measured: Option<CycleFeatures>,
    pub simulated: Option<CycleFeatures>,
    /// `simulated - measured` frequency, relative.
    pub frequency_error: Option<f64>,
    /// Phase of the simulated displacer relative to the measured one over the last cycles of
    /// the block (rad; the accumulated phase drift of the free run).
    pub x_phase_lag: Option<f64>,
    pub seconds: f64,
    #[serde(skip)]
    pub series: Vec<Series>,
}

impl FreeRun {
    /// Fit percentage of a channel on `free_run` or `free_run_short`.
    pub fn fit_percent(&self, channel: &str, block: &str) -> Option<f64> {
        self.fits
            .iter()
            .find(|f| f.channel == channel && f.block == block)
            .map(|f| f.fit_percent)
    }
}

/// The sample range `[a, b]` from `block.0` to `end`, at least `need` samples (the error
/// names the block and `stage`).
pub(super) fn sample_range(
    data: &Measured,
    block: (f64, f64),
    end: f64,
    stage: &str,
    need: usize,
) -> Result<(usize, usize), FitError> {
    let (t0, dt) = (data.t[0], data.dt());
    let nt = data.t.len();
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(nt - 1);
    let (a, b) = (idx(block.0), idx(end));
    if b + 1 < a + need {
        return Err(FitError::ShortBlock {
            stage: stage.into(),
            from: block.0,
            to: block.1,
            samples: b + 1 - a.min(b + 1),
            need,
        });
    }
    Ok((a, b))
}

/// Fits per channel over the first `len` samples of each block `(label, len)`.
fn block_fits(
    meas: &[(String, Vec<f64>)],
    sim: &[(String, Vec<f64>)],
    blocks: [(&str, usize); 2],
) -> Vec<ChannelFit> {
    let mut fits = Vec::new();
    for (label, len) in blocks {
        for ((n, y), (_, yh)) in meas.iter().zip(sim) {
            fits.push(ChannelFit::plain(n, label, &y[..len], &yh[..len]));
        }
    }
    fits
}

/// Measured and simulated series of each channel over the samples `a..=b`.
fn block_series(
    meas: &[(String, Vec<f64>)],
    sim: &[(String, Vec<f64>)],
    t: &[f64],
    (a, b): (usize, usize),
) -> Vec<Series> {
    meas.iter()
        .zip(sim)
        .map(|((n, y), (_, yh))| Series {
            channel: n.clone(),
            t: (a..=b).map(|i| t[i]).collect(),
            measured: y.clone(),
            model: yh.clone(),
        })
        .collect()
}

/// Phase of the simulated `x` relative to the measured one over the last `cycles` of `len`
/// samples at frequency `f`.
fn phase_lag(meas: &[f64], sim: &[f64], dt: f64, f: f64, cycles: f64, len: usize) -> f64 {
    let m = ((cycles / f / dt).round() as usize).clamp(10, len);
    let k = len - m;
    let (_, pm) = fundamental(&meas[k..], dt, f);
    let (_, ps) = fundamental(&sim[k..], dt, f);
    wrap(ps - pm)
}

/// Simulate `model` at `p` from `x0` over `steps` samples `dt` apart.
fn simulate_steps(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    (steps, dt): (usize, f64),
    opts: &SimOptions,
) -> Result<Trajectory, FitError> {
    let samples: Vec<f64> = (0..=steps).map(|k| k as f64 * dt).collect();
    simulate(model, p, x0, samples[samples.len() - 1], &samples, opts).map_err(|source| {
        FitError::Sim {
            stage: "free run".into(),
            source,
        }
    })
}

/// Simulate `model` at `p` from the measured state at the start of `block` and compare.
pub fn free_run(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    off: &SensorOffsets,
    block: (f64, f64),
    opts: &FreeRunOptions,
) -> Result<FreeRun, FitError> {
    let clock = Instant::now();
    let name = "free run";
    let ch = outputs(model, data)?;
    let dt = data.dt();
    let (a, b) = sample_range(data, block, block.1, name, 11)?;
    let h = ((opts.smooth / dt).round() as usize).max(3);
    let x0 = measured_state(model, p, data, off, a, h)?;
    let traj = simulate_steps(model, p, &x0, (b - a, dt), &opts.sim)?;
    let meas: Vec<(String, Vec<f64>)> = ch
        .iter()
        .map(|c| (c.name.clone(), c.data[a..=b].to_vec()))
        .collect();
    let sim = predicted(model, p, &ch, &traj.x, off);
    let measured = cycle_features(&meas, dt);
    let simulated = cycle_features(&sim, dt);
    let f_meas = measured
        .as_ref()
        .map(|m| m.frequency)
        .or_else(|| crate::signal::cycle_frequency(&data.x.as_ref().expect("checked")[..], dt));
    let short = f_meas
        .map(|f| opts.cycles / f)
        .unwrap_or(block.1 - block.0)
        .min(block.1 - block.0);
    let ns = ((short / dt).round() as usize).clamp(10, b - a + 1);
    let fits = block_fits(
        &meas,
        &sim,
        [("free_run", b - a + 1), ("free_run_short", ns)],
    );
    let frequency_error = match (&measured, &simulated) {
        (Some(m), Some(s)) => Some(s.frequency / m.frequency - 1.0),
        _ => None,
    };
    let x_phase_lag =
        f_meas.map(|f| phase_lag(&meas[0].1, &sim[0].1, dt, f, opts.cycles, b - a + 1));
    Ok(FreeRun {
        x_phase_lag,
        block,
        short_window: ns as f64 * dt,
        initial_state: model.state_names().into_iter().zip(x0).collect(),
        fits,
        measured,
        simulated,
        frequency_error,
        seconds: clock.elapsed().as_secs_f64(),
        series: block_series(&meas, &sim, &data.t, (a, b)),
    })
}
