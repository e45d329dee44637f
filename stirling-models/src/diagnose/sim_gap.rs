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

use rand::{rngs::StdRng, Rng, SeedableRng};
use serde::Serialize;
use stirling_dsl::Model;

use crate::data::Measured;
use crate::fit::free_run::{free_run, FreeRunOptions, SensorOffsets};
use crate::signal::{dft, first_order_lag, upward_crossings, Crossing};

/// Bins of the residual by phase of the cycle.
pub const PHASE_BINS: usize = 36;

/// The features compared, with their units of error.
const FEATURES: [(&str, &str); 7] = [
    ("frequency", "%"),
    ("x amplitude", "%"),
    ("y amplitude", "%"),
    ("p amplitude", "%"),
    ("x-y phase", "deg"),
    ("cycle work", "%"),
    ("growth rate", "1/s"),
];

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
                "\nclosure of the simulated gap by `{after}`: {:.2} [{:.2}, {:.2}] (1 - sum of squared feature errors after / before)\n",
                c.value, c.ci_low, c.ci_high
            ));
        }
        s
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
    #[error("the free run of the {which} model failed: {why}")]
    FreeRun { which: &'static str, why: String },
    #[error("the held-out block holds {found} cycles of the {which} series; the simulated gap needs at least 3")]
    TooFewCycles { which: &'static str, found: usize },
}

/// The cycles of `x` as `(start, length, u0)` in samples: between consecutive crossings,
/// with `u0` the fraction of the cycle at which the cycle's fundamental crosses upward
/// (the phase reference: independent of the record's mean, which sets the crossings).
fn cycles_of(x: &[f64], ups: &[Crossing]) -> Vec<(f64, f64, f64)> {
    ups.windows(2)
        .map(|w| (w[0].at, w[1].at - w[0].at))
        .map(|(a, len)| {
            let (mut re, mut im) = (0.0, 0.0);
            for k in (a.ceil() as usize)..((a + len).ceil() as usize).min(x.len()) {
                let u = std::f64::consts::TAU * (k as f64 - a) / len;
                re += x[k] * u.cos();
                im -= x[k] * u.sin();
            }
            let theta = im.atan2(re);
            let u0 = -(theta + std::f64::consts::FRAC_PI_2) / std::f64::consts::TAU;
            (a, len, u0 - u0.round())
        })
        .collect()
}

/// The mean of `v` by phase of the cycle over `cycles`: each cycle interpolated linearly at
/// the `PHASE_BINS` bin centres (so that the sampling grid does not bias the shape).
fn phase_profile(v: &[f64], cycles: &[(f64, f64, f64)]) -> Vec<f64> {
    let at = |t: f64| {
        let i = t.floor() as usize;
        (i + 1 < v.len() && t >= 0.0).then(|| v[i] + (t - t.floor()) * (v[i + 1] - v[i]))
    };
    (0..PHASE_BINS)
        .map(|bin| {
            let phase = (bin as f64 + 0.5) / PHASE_BINS as f64;
            let vals: Vec<f64> = cycles
                .iter()
                .filter_map(|&(a, len, u0)| at(a + (u0 + phase) * len))
                .collect();
            vals.iter().sum::<f64>() / vals.len() as f64
        })
        .collect()
}

/// One series' per-cycle features and its `x`, `y`, `p` waveforms by phase of the cycle.
struct Cycles {
    rows: Vec<[f64; 7]>,
    profiles: [Vec<f64>; 3],
}

impl Cycles {
    fn of(x: &[f64], y: &[f64], p: &[f64], dt: f64, area: (f64, f64)) -> Cycles {
        let cycles = cycles_of(x, &upward_crossings(x));
        Cycles {
            rows: cycle_rows(x, y, p, dt, area),
            profiles: [x, y, p].map(|v| phase_profile(v, &cycles)),
        }
    }

    /// Measured minus simulated waveform by phase, per channel.
    fn residual(&self, sim: &Cycles) -> [Vec<f64>; 3] {
        std::array::from_fn(|c| {
            self.profiles[c]
                .iter()
                .zip(&sim.profiles[c])
                .map(|(m, s)| m - s)
                .collect()
        })
    }
}

/// Per-cycle features: one row per cycle, in the order of [`FEATURES`] (growth: `NaN` on
/// the last cycle).
fn cycle_rows(x: &[f64], y: &[f64], p: &[f64], dt: f64, area: (f64, f64)) -> Vec<[f64; 7]> {
    let ups = upward_crossings(x);
    let half_pp = |v: &[f64]| {
        0.5 * (v.iter().cloned().fold(f64::MIN, f64::max)
            - v.iter().cloned().fold(f64::MAX, f64::min))
    };
    let (a, ar) = area;
    let mut rows: Vec<[f64; 7]> = ups
        .windows(2)
        .map(|w| {
            let (i, j) = (w[0].index, w[1].index);
            let per = (w[1].at - w[0].at) * dt;
            let (xr, xi) = dft(&x[i..j], (j - i) as f64, 1);
            let (yr, yi) = dft(&y[i..j], (j - i) as f64, 1);
            let mut phase = (xi.atan2(xr) - yi.atan2(yr)).to_degrees();
            phase -= 360.0 * (phase / 360.0).round();
            let work: f64 = (i..j)
                .map(|k| {
                    let dv = -(ar * (x[k + 1] - x[k]) + (a - ar) * (y[k + 1] - y[k]));
                    0.5 * (p[k] + p[k + 1]) * dv
                })
                .sum();
            [
                1.0 / per,
                half_pp(&x[i..j]),
                half_pp(&y[i..j]),
                half_pp(&p[i..j]),
                phase,
                work,
                f64::NAN,
            ]
        })
        .collect();
    for k in 0..rows.len().saturating_sub(1) {
        rows[k][6] = (rows[k + 1][1] / rows[k][1]).ln() * rows[k][0];
    }
    rows
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
    let fr = free_run(model, m.p, data, off, block, &FreeRunOptions::default()).map_err(|e| {
        SimGapError::FreeRun {
            which,
            why: e.to_string(),
        }
    })?;
    let dt = data.dt();
    let get = |ch: &str| fr.series.iter().find(|s| s.channel == ch);
    let (Some(sx), Some(sy), Some(sp)) = (get("x"), get("y"), get("p")) else {
        return Err(SimGapError::FreeRun {
            which,
            why: "the free run has no x, y or p series".into(),
        });
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
fn interval(value: f64, mut boot: Vec<f64>) -> FeatureError {
    boot.retain(|v| v.is_finite());
    boot.sort_by(f64::total_cmp);
    let q = |p: f64| {
        boot.get(((boot.len() as f64 - 1.0) * p).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    FeatureError {
        value,
        ci_low: q(0.025),
        ci_high: q(0.975),
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
    let (meas_c, sim_bc) = simulate_rows(model, data, off, block, before, "calibrated", area)?;
    let sim_ac = match after {
        Some((_, m)) => Some(simulate_rows(model, data, off, block, m, "effect", area)?.1),
        None => None,
    };
    let res_b = meas_c.residual(&sim_bc);
    let res_a = sim_ac.as_ref().map(|s| meas_c.residual(s));
    let phase_residuals = ["x", "y", "p"]
        .iter()
        .enumerate()
        .map(|(c, ch)| PhaseResidual {
            channel: ch.to_string(),
            before: res_b[c].clone(),
            after: res_a.as_ref().map(|r| r[c].clone()),
        })
        .collect();
    let (meas, sim_b, sim_a) = (meas_c.rows, sim_bc.rows, sim_ac.map(|s| s.rows));
    let mut k = meas.len().min(sim_b.len());
    if let Some(s) = &sim_a {
        k = k.min(s.len());
    }
    if k < 3 {
        let (which, found) = if meas.len() < 3 {
            ("measured", meas.len())
        } else {
            ("simulated", k)
        };
        return Err(SimGapError::TooFewCycles { which, found });
    }
    let eb = errors(&meas, &sim_b, k);
    let ea = sim_a.as_ref().map(|s| errors(&meas, s, k));
    let all: Vec<usize> = (0..k).collect();
    let f0 = meas[..k].iter().map(|r| r[0]).sum::<f64>() / k as f64;
    let mut rng = StdRng::seed_from_u64(seed);
    let draws: Vec<Vec<usize>> = (0..resamples)
        .map(|_| (0..k).map(|_| rng.gen_range(0..k)).collect())
        .collect();
    let feature = |e: &[[f64; 7]], f: usize| {
        let boot = draws.iter().map(|d| mean_errors(e, d)[f]).collect();
        interval(mean_errors(e, &all)[f], boot)
    };
    let measured = mean_errors(&meas[..k].to_vec(), &all);
    let rows = FEATURES
        .iter()
        .enumerate()
        .map(|(f, (name, unit))| {
            let pct = if *unit == "%" { 100.0 } else { 1.0 };
            let scaled = |v: FeatureError| FeatureError {
                value: v.value * pct,
                ci_low: v.ci_low * pct,
                ci_high: v.ci_high * pct,
            };
            FeatureRow {
                feature: name.to_string(),
                unit: unit.to_string(),
                measured: measured[f],
                before: scaled(feature(&eb, f)),
                after: ea.as_ref().map(|e| scaled(feature(e, f))),
            }
        })
        .collect();
    let closure = ea.as_ref().map(|ea| {
        let c = |d: &[usize]| 1.0 - size(&mean_errors(ea, d), f0) / size(&mean_errors(&eb, d), f0);
        interval(c(&all), draws.iter().map(|d| c(d)).collect())
    });
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

    /// A growing oscillation: x leads y by 60 degrees, p in phase with x.
    fn series(f: f64, growth: f64, n: usize, dt: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let w = 2.0 * std::f64::consts::PI * f;
        let t = |k: usize| k as f64 * dt;
        let env = |k: usize| 0.01 * (growth * t(k)).exp();
        let x = (0..n).map(|k| env(k) * (w * t(k)).sin()).collect();
        let y = (0..n)
            .map(|k| 0.5 * env(k) * (w * t(k) - 60f64.to_radians()).sin())
            .collect();
        let p = (0..n)
            .map(|k| 1e5 + 1e7 * env(k) * (w * t(k)).sin())
            .collect();
        (x, y, p)
    }

    #[test]
    fn cycle_rows_read_frequency_phase_and_growth() {
        let dt = 1.0 / 2000.0;
        let (x, y, p) = series(12.5, 0.8, 2000, dt);
        let rows = cycle_rows(&x, &y, &p, dt, (0.01, 0.002));
        assert!(rows.len() >= 10, "{} cycles", rows.len());
        for r in &rows[..rows.len() - 1] {
            assert!((r[0] / 12.5 - 1.0).abs() < 1e-3, "frequency {}", r[0]);
            assert!((r[4] - 60.0).abs() < 1.5, "phase {}", r[4]);
            assert!((r[6] - 0.8).abs() < 0.05, "growth {}", r[6]);
        }
    }

    #[test]
    fn phase_residual_is_the_waveform_difference_whatever_the_frequency() {
        let dt = 1.0 / 2000.0;
        let (x, y, p) = series(12.5, 0.0, 2000, dt);
        let (xs, ys, ps) = series(13.0, 0.0, 2000, dt);
        let area = (0.01, 0.002);
        let (m, s) = (
            Cycles::of(&x, &y, &p, dt, area),
            Cycles::of(&xs, &ys, &ps, dt, area),
        );
        for (r, amp) in m.residual(&s).iter().zip([0.01, 0.005, 1e5]) {
            let worst = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(
                worst < 0.02 * amp,
                "same shape, other frequency: {worst} of {amp}"
            );
        }
        let scaled: Vec<f64> = x.iter().map(|v| 0.9 * v).collect();
        let s = Cycles::of(&scaled, &y, &p, dt, area);
        let rx = &m.residual(&s)[0];
        let peak = rx.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(
            (peak / 0.001 - 1.0).abs() < 0.05,
            "10 % of a 1 cm amplitude: {peak}"
        );
    }

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
