//! Per-cycle features of a record (or a simulation of it) and its waveforms by phase of the cycle:
//! what the simulated gap ([`crate::diagnose::sim_gap`]) compares, cycle by cycle.
//!
//! Cycles run between upward crossings of the displacer `x`. Each gives the frequency, the
//! amplitudes of `x`, `y`, `p` (half the peak-to-peak), the phase by which `x` leads `y`
//! (fundamental over the cycle), the gas work `oint p dV` with `dV = -(Ar dx + (A - Ar)
//! dy)`, and the growth rate `ln(a_{k+1} / a_k) f_k` of the displacer amplitude.

use crate::signal::{dft, upward_crossings, Crossing};

/// Bins of the residual by phase of the cycle.
pub const PHASE_BINS: usize = 36;

/// The features compared, with their units of error.
pub(super) const FEATURES: [(&str, &str); 7] = [
    ("frequency", "%"),
    ("x amplitude", "%"),
    ("y amplitude", "%"),
    ("p amplitude", "%"),
    ("x-y phase", "deg"),
    ("cycle work", "%"),
    ("growth rate", "1/s"),
];

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
pub(super) struct Cycles {
    pub rows: Vec<[f64; 7]>,
    pub profiles: [Vec<f64>; 3],
}

impl Cycles {
    pub fn of(x: &[f64], y: &[f64], p: &[f64], dt: f64, area: (f64, f64)) -> Cycles {
        let cycles = cycles_of(x, &upward_crossings(x));
        Cycles {
            rows: cycle_rows(x, y, p, dt, area),
            profiles: [x, y, p].map(|v| phase_profile(v, &cycles)),
        }
    }

    /// Measured minus simulated waveform by phase, per channel.
    pub fn residual(&self, sim: &Cycles) -> [Vec<f64>; 3] {
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
}
