//! Bode and Nyquist data of `L(jw)` on a frequency grid, and the grid itself.
//!
//! The grid is logarithmic over the span of the poles (`0.01 min |s|` to `100 max |s|`),
//! refined around every lightly damped pair (`w = Im s + t |Re s|`, `|t| <= 5`) so that
//! resonant phase swings are resolved.

use nalgebra::Complex;
use serde::{Deserialize, Serialize};

use super::poles::Pole;

/// Bode data: magnitude in dB, phase in degrees (continuous, starting in `(-180, 180]`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bode {
    pub w: Vec<f64>,
    pub mag_db: Vec<f64>,
    pub phase_deg: Vec<f64>,
}

/// Nyquist data: `L(jw)` for `w >= 0` on the grid.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Nyquist {
    pub w: Vec<f64>,
    pub re: Vec<f64>,
    pub im: Vec<f64>,
}

/// `count` points per decade from `lo` to `hi` (inclusive).
pub fn log_grid(lo: f64, hi: f64, per_decade: usize) -> Vec<f64> {
    let decades = (hi / lo).log10().max(0.0);
    let m = ((decades * per_decade as f64).ceil() as usize).max(1);
    (0..=m)
        .map(|i| lo * (hi / lo).powf(i as f64 / m as f64))
        .collect()
}

/// The analysis grid for loops whose open- and closed-loop poles are `poles`.
pub fn frequency_grid(poles: &[Pole], per_decade: usize) -> Vec<f64> {
    let mags: Vec<f64> = poles
        .iter()
        .map(|p| p.natural_rad_s)
        .filter(|&m| m > 1e-9)
        .collect();
    let lo = mags.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = mags.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > 0.0 {
        (lo * 1e-2, hi * 1e2)
    } else {
        (1e-2, 1e4)
    };
    let mut w = log_grid(lo, hi, per_decade);
    for p in poles
        .iter()
        .filter(|p| p.im > 0.0 && p.damping_ratio.abs() < 0.5)
    {
        w.extend(
            (-20..=20)
                .map(|t| p.im + t as f64 * 0.25 * p.re.abs())
                .filter(|&v| v > 0.0),
        );
    }
    w.sort_by(f64::total_cmp);
    w.dedup_by(|b, a| (*b - *a).abs() <= 1e-12 * a.abs());
    w
}

/// Bode data of `l` on `w`.
pub fn bode(l: &dyn Fn(f64) -> Complex<f64>, w: &[f64]) -> Bode {
    let vals: Vec<Complex<f64>> = w.iter().map(|&w| l(w)).collect();
    let mut phase = Vec::with_capacity(w.len());
    let mut prev: Option<f64> = None;
    for v in &vals {
        let mut a = v.arg().to_degrees();
        if let Some(p) = prev {
            a += 360.0 * ((p - a) / 360.0).round();
        }
        phase.push(a);
        prev = Some(a);
    }
    Bode {
        w: w.to_vec(),
        mag_db: vals.iter().map(|v| 20.0 * v.norm().log10()).collect(),
        phase_deg: phase,
    }
}

/// Nyquist data of `l` on `w`.
pub fn nyquist(l: &dyn Fn(f64) -> Complex<f64>, w: &[f64]) -> Nyquist {
    let vals: Vec<Complex<f64>> = w.iter().map(|&w| l(w)).collect();
    Nyquist {
        w: w.to_vec(),
        re: vals.iter().map(|v| v.re).collect(),
        im: vals.iter().map(|v| v.im).collect(),
    }
}
