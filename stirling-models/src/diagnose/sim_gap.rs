//! The gap where a user sees it: the calibrated model *simulated on its own* from the
//! measured state at the start of the held-out block, against the record, cycle by cycle.
//!
//! Each held-out cycle (upward crossings of the displacer) gives the frequency, the
//! amplitudes of `x`, `y`, `p` (half the peak-to-peak), the phase by which `x` leads `y`
//! (fundamental over the cycle), the gas work `oint p dV` with
//! `dV = -(Ar dx + (A - Ar) dy)`, and the growth rate `ln(a_{k+1} / a_k) f_k` of the
//! displacer amplitude. The simulation's `k`-th cycle is compared with the record's `k`-th:
//! the error of a feature is the mean over the cycles of `model - measured` (relative for
//! frequency, amplitudes and work; in degrees for the phase; in 1/s for the growth rate),
//! with a 95 % bootstrap interval over the cycles.
//!
//! "How far it shrinks" is each feature's error before (the calibrated nominal model) and
//! after (the model with the leading effect fitted), and one closure: `1 - D_after /
//! D_before` with `D = sum_f e_f^2` over the dimensionless errors (the phase in radians, the
//! growth rate per cycle), resampled with the same cycles for its interval.

use serde::Serialize;
use stirling_dsl::Model;

use super::cycle_features::{Cycles, FEATURES};
use crate::data::Measured;
use crate::fit::free_run::{free_run, FreeRunOptions, SensorOffsets};
use crate::fit::FitError;
use crate::signal::{first_order_lag, percentile_interval};

/// One feature's error (model minus measured) with its 95 % interval.
#[derive(Clone, Debug, Serialize)]
pub struct FeatureError {
    pub value: f64,
    pub ci_low: f64,
    pub ci_high: f64,
}

/// One row of the feature table.
#[derive(Clone, Debug, Serialize)]
pub struct FeatureRow {
    pub feature: String,
    /// Unit of the errors (`%`: relative to the measured value).
    pub unit: String,
    /// The measured mean over the held-out cycles (frequency in Hz, amplitudes in m and Pa,
    /// phase in degrees, work in J, growth rate in 1/s).
    pub measured: f64,
    pub before: FeatureError,
    pub after: Option<FeatureError>,
}

/// One channel's residual (measured minus model) by phase of the cycle, SI units
/// (m, Pa): the record's mean waveform over its cycles minus the simulation's over its own.
#[derive(Clone, Debug, Serialize)]
pub struct PhaseResidual {
    pub channel: String,
    pub before: Vec<f64>,
    pub after: Option<Vec<f64>>,
}

/// The simulated gap on the held-out block.
#[derive(Clone, Debug, Serialize)]
pub struct SimulationGap {
    /// The block (s) and the cycles compared.
    pub block: (f64, f64),
    pub cycles: usize,
    pub rows: Vec<FeatureRow>,
    /// The effect of the "after" column, if any.
    pub effect: Option<String>,
    /// `1 - D_after / D_before` with its 95 % interval.
    pub closure: Option<FeatureError>,
    /// The residual by phase of the cycle for `x`, `y`, `p`.
    pub phase_residuals: Vec<PhaseResidual>,
}

impl SimulationGap {
    /// The feature table as Markdown (readable as plain text too).
    pub fn markdown(&self) -> String {
        let ci =
            |e: &FeatureError| format!("{:+.3} [{:+.3}, {:+.3}]", e.value, e.ci_low, e.ci_high);
        let after = self.effect.as_deref().unwrap_or("-");
        let mut s = format!(
            "| feature | measured | error before | error after `{after}` | unit |\n|---|---|---|---|---|\n"
        );
        for r in &self.rows {
            s.push_str(&format!(
                "| {} | {:.4e} | {} | {} | {} |\n",
                r.feature,
                r.measured,
                ci(&r.before),
                r.after.as_ref().map_or("-".into(), ci),
                r.unit
            ));
        }
        if let Some(c) = &self.closure {
            s.push_str(&format!(
                "\nclosure of the simulated gap by `{after}`: {:.2} [{:.2}, {:.2}] (1 - sum of squared feature errors after / before){}\n",
                c.value,
                c.ci_low,
                c.ci_high,
                self.closure_note()
            ));
        }
        s
    }

    /// What the closure interval says, when it says less than its value suggests.
    fn closure_note(&self) -> &'static str {
        let Some(c) = &self.closure else { return "" };
        let off = |e: &FeatureError| e.ci_low > 0.0 || e.ci_high < 0.0;
        let offs = self.rows.iter().filter(|r| off(&r.before)).count();
        if offs == 0 {
            ": no feature is off before (every interval holds 0): the free run already matches the record within its cycle-to-cycle scatter, so there is nothing to close in simulation"
        } else if c.ci_low <= 0.0 && c.ci_high >= 0.0 {
            ": the interval holds 0: no measurable change in simulation"
        } else if c.ci_high < 0.0 {
            ": the simulated gap grew: the effect, fitted on the driven subsystems, does not carry over to the free run"
        } else {
            ""
        }
    }
}

/// A model to simulate: its parameters and the sensor distortions of its outputs.
pub struct Simulated<'a> {
    pub p: &'a [f64],
    /// Pressure-transducer lag (s) and position gains applied to the simulated outputs.
    pub tau_p: f64,
    pub gain: (f64, f64),
}

/// Why the simulated gap could not be measured.
#[derive(Clone, Debug, thiserror::Error)]
pub enum SimGapError {
    #[error("the free run of the {which} model failed: {source}")]
    FreeRun {
        which: &'static str,
        #[source]
        source: FitError,
    },
    #[error("the free run of the {which} model has no x, y or p series")]
    Channels { which: &'static str },
    #[error("the held-out block holds {found} cycles of the {which} series; the simulated gap needs at least 3")]
    TooFewCycles { which: &'static str, found: usize },
}

/// The free run of one model on the block, as per-cycle features.
fn simulate_rows(
    model: &dyn Model,
    data: &Measured,
    off: &SensorOffsets,
    block: (f64, f64),
    m: &Simulated,
    which: &'static str,
    area: (f64, f64),
) -> Result<(Cycles, Cycles), SimGapError> {
    let fr = free_run(model, m.p, data, off, block, &FreeRunOptions::default())
        .map_err(|source| SimGapError::FreeRun { which, source })?;
    let dt = data.dt();
    let get = |ch: &str| fr.series.iter().find(|s| s.channel == ch);
    let (Some(sx), Some(sy), Some(sp)) = (get("x"), get("y"), get("p")) else {
        return Err(SimGapError::Channels { which });
    };
    let scale = |v: &[f64], o: f64, g: f64| v.iter().map(|u| (u - o) * (1.0 + g) + o).collect();
    let xm: Vec<f64> = scale(&sx.model, off.x, m.gain.0);
    let ym: Vec<f64> = scale(&sy.model, off.y, m.gain.1);
    let pm = first_order_lag(&sp.model, dt, m.tau_p);
    let meas = Cycles::of(&sx.measured, &sy.measured, &sp.measured, dt, area);
    let sim = Cycles::of(&xm, &ym, &pm, dt, area);
    Ok((meas, sim))
}

/// Per-cycle errors of the simulation against the record (first `k` cycles).
fn errors(meas: &[[f64; 7]], sim: &[[f64; 7]], k: usize) -> Vec<[f64; 7]> {
    (0..k)
        .map(|c| {
            let mut e = [0.0; 7];
            for f in 0..7 {
                let d = sim[c][f] - meas[c][f];
                e[f] = match FEATURES[f].1 {
                    "%" => d / meas[c][f],
                    _ => d,
                };
            }
            e
        })
        .collect()
}

/// Mean error per feature over the cycles `idx` (growth: the cycles that have one).
fn mean_errors(e: &[[f64; 7]], idx: &[usize]) -> [f64; 7] {
    let mut out = [0.0; 7];
    for f in 0..7 {
        let v: Vec<f64> = idx
            .iter()
            .map(|&c| e[c][f])
            .filter(|v| v.is_finite())
            .collect();
        out[f] = v.iter().sum::<f64>() / v.len().max(1) as f64;
    }
    out
}

/// Dimensionless size of a set of mean errors (phase in rad, growth per cycle at `f0`).
fn size(m: &[f64; 7], f0: f64) -> f64 {
    (0..7)
        .map(|f| match f {
            4 => m[f].to_radians(),
            6 => m[f] / f0,
            _ => m[f],
        })
        .map(|v| v * v)
        .sum()
}

/// Percentile interval of bootstrap values around `value`.
fn interval(value: f64, boot: Vec<f64>) -> FeatureError {
    let (ci_low, ci_high) = percentile_interval(boot);
    FeatureError {
        value,
        ci_low,
        ci_high,
    }
}

/// Measured minus simulated waveform by phase, per channel, before and after.
fn phase_residuals(meas: &Cycles, before: &Cycles, after: Option<&Cycles>) -> Vec<PhaseResidual> {
    let res_b = meas.residual(before);
    let res_a = after.map(|s| meas.residual(s));
    ["x", "y", "p"]
        .iter()
        .enumerate()
        .map(|(c, ch)| PhaseResidual {
            channel: ch.to_string(),
            before: res_b[c].clone(),
            after: res_a.as_ref().map(|r| r[c].clone()),
        })
        .collect()
}

/// The cycles every series has (at least 3).
fn common_cycles(
    meas: &[[f64; 7]],
    before: &[[f64; 7]],
    after: Option<&[[f64; 7]]>,
) -> Result<usize, SimGapError> {
    let k = meas
        .len()
        .min(before.len())
        .min(after.map_or(usize::MAX, |s| s.len()));
    if k >= 3 {
        return Ok(k);
    }
    let (which, found) = if meas.len() < 3 {
        ("measured", meas.len())
    } else {
        ("simulated", k)
    };
    Err(SimGapError::TooFewCycles { which, found })
}

/// Resamples of the cycles (with replacement), shared by every feature and the closure so
/// that their intervals come from the same draws.
struct Bootstrap {
    all: Vec<usize>,
    draws: Vec<Vec<usize>>,
    /// The mean measured frequency (scales the growth rate per cycle).
    f0: f64,
}

impl Bootstrap {
    fn new(meas: &[[f64; 7]], k: usize, resamples: usize, seed: u64) -> Self {
        Bootstrap {
            all: (0..k).collect(),
            draws: crate::signal::resamples(k, resamples, seed),
            f0: meas[..k].iter().map(|r| r[0]).sum::<f64>() / k as f64,
        }
    }

    /// Feature `f`'s mean error with its interval, in the feature's unit (`%` scaled).
    fn feature(&self, e: &[[f64; 7]], f: usize) -> FeatureError {
        let boot = self.draws.iter().map(|d| mean_errors(e, d)[f]).collect();
        let v = interval(mean_errors(e, &self.all)[f], boot);
        let pct = if FEATURES[f].1 == "%" { 100.0 } else { 1.0 };
        FeatureError {
            value: v.value * pct,
            ci_low: v.ci_low * pct,
            ci_high: v.ci_high * pct,
        }
    }

    /// `1 - D_after / D_before` with its interval.
    fn closure(&self, eb: &[[f64; 7]], ea: &[[f64; 7]]) -> FeatureError {
        let c = |d: &[usize]| {
            1.0 - size(&mean_errors(ea, d), self.f0) / size(&mean_errors(eb, d), self.f0)
        };
        interval(c(&self.all), self.draws.iter().map(|d| c(d)).collect())
    }
}

/// The simulated gap of the calibrated model (`before`) and, if given, of the model with the
/// leading effect (`after`), on the held-out `block` (s).
#[allow(clippy::too_many_arguments)]
pub fn simulation_gap(
    model: &dyn Model,
    data: &Measured,
    off: &SensorOffsets,
    block: (f64, f64),
    before: &Simulated,
    after: Option<(&str, &Simulated)>,
    resamples: usize,
    seed: u64,
) -> Result<SimulationGap, SimGapError> {
    let param = |n: &str| model.param_index(n).map_or(0.0, |i| before.p[i]);
    let area = (param("A"), param("Ar"));
    // the two free runs are independent: in parallel
    let (calibrated, effect) = rayon::join(
        || simulate_rows(model, data, off, block, before, "calibrated", area),
        || after.map(|(_, m)| simulate_rows(model, data, off, block, m, "effect", area)),
    );
    let (meas_c, sim_bc) = calibrated?;
    let sim_ac = effect.transpose()?.map(|r| r.1);
    let phase_residuals = phase_residuals(&meas_c, &sim_bc, sim_ac.as_ref());
    let (meas, sim_b, sim_a) = (meas_c.rows, sim_bc.rows, sim_ac.map(|s| s.rows));
    let k = common_cycles(&meas, &sim_b, sim_a.as_deref())?;
    let boot = Bootstrap::new(&meas, k, resamples, seed);
    let eb = errors(&meas, &sim_b, k);
    let ea = sim_a.as_ref().map(|s| errors(&meas, s, k));
    let measured = mean_errors(&meas[..k], &boot.all);
    let rows = FEATURES
        .iter()
        .enumerate()
        .map(|(f, (name, unit))| FeatureRow {
            feature: name.to_string(),
            unit: unit.to_string(),
            measured: measured[f],
            before: boot.feature(&eb, f),
            after: ea.as_ref().map(|e| boot.feature(e, f)),
        })
        .collect();
    let closure = ea.as_ref().map(|ea| boot.closure(&eb, ea));
    Ok(SimulationGap {
        block,
        cycles: k,
        rows,
        effect: after.map(|(n, _)| n.to_string()),
        closure,
        phase_residuals,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_are_relative_and_the_closure_measures_the_shrink() {
        let meas = vec![[10.0, 1.0, 1.0, 1.0, 60.0, 1.0, 0.5]; 6];
        let mut before = meas.clone();
        let mut after = meas.clone();
        for r in &mut before {
            r[0] = 11.0; // +10 %
            r[4] = 70.0; // +10 deg
        }
        for r in &mut after {
            r[0] = 10.5; // +5 %
            r[4] = 65.0; // +5 deg
        }
        let (eb, ea) = (errors(&meas, &before, 6), errors(&meas, &after, 6));
        let all: Vec<usize> = (0..6).collect();
        let (mb, ma) = (mean_errors(&eb, &all), mean_errors(&ea, &all));
        assert!((mb[0] - 0.1).abs() < 1e-12 && (mb[4] - 10.0).abs() < 1e-12);
        let closure = 1.0 - size(&ma, 10.0) / size(&mb, 10.0);
        assert!((closure - 0.75).abs() < 1e-12, "closure {closure}");
    }
}
