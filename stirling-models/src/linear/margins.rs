//! Gain and phase margins of a negative-feedback loop `L(jw)`, as MATLAB's `margin`.
//!
//! - Phase crossovers: `L(jw)` real and negative (`arg L = -180 deg mod 360`); the gain margin
//!   there is `Gm = -20 log10 |L|` dB. `w = 0` counts when `L(0)` is real and negative.
//! - Gain crossovers: `|L(jw)| = 1`; the phase margin is `Pm = 180 + arg L` wrapped into
//!   `(-180, 180]` degrees.
//! - Selected: the gain margin with the smallest `|Gm|` in dB and the phase margin with the
//!   smallest `|Pm|` (MATLAB's choice). An unstable closed loop shows up as a negative margin,
//!   but a positive one may be selected when several crossovers exist: all are reported.
//!
//! Crossovers are bracketed on a frequency grid (sign changes of `Im L` and of `ln |L|`) and
//! refined by the Illinois variant of regula falsi to a relative width of `1e-12`.

use nalgebra::Complex;
use serde::{Deserialize, Serialize};

/// A gain margin at a phase crossover.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GainMargin {
    pub gain_db: f64,
    pub phase_crossover_rad_s: f64,
}

/// A phase margin at a gain crossover.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhaseMargin {
    pub phase_deg: f64,
    pub gain_crossover_rad_s: f64,
}

/// The selected margins (`None`: no crossover, MATLAB's `Inf`/`NaN`) and all crossovers.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Margins {
    pub gain_db: Option<f64>,
    pub phase_crossover_rad_s: Option<f64>,
    pub phase_deg: Option<f64>,
    pub gain_crossover_rad_s: Option<f64>,
    pub all_gain: Vec<GainMargin>,
    pub all_phase: Vec<PhaseMargin>,
}

/// Margins of `l` (evaluated at `w` rad/s) bracketed on the increasing `grid`.
pub fn margins(l: &dyn Fn(f64) -> Complex<f64>, grid: &[f64]) -> Margins {
    let mut all_gain = Vec::new();
    if let Some(g) = at_zero(l) {
        all_gain.push(g);
    }
    let mut all_phase = Vec::new();
    let vals: Vec<Complex<f64>> = grid.iter().map(|&w| l(w)).collect();
    for i in 1..grid.len() {
        let (w0, w1, l0, l1) = (grid[i - 1], grid[i], vals[i - 1], vals[i]);
        if l0.im.signum() != l1.im.signum() || l1.im == 0.0 {
            let w = refine(&|w| l(w).im, w0, w1, l0.im, l1.im);
            let lw = l(w);
            if lw.re < 0.0 {
                all_gain.push(GainMargin {
                    gain_db: -20.0 * lw.norm().log10(),
                    phase_crossover_rad_s: w,
                });
            }
        }
        let (g0, g1) = (l0.norm().ln(), l1.norm().ln());
        if g0.signum() != g1.signum() || g1 == 0.0 {
            let w = refine(&|w| l(w).norm().ln(), w0, w1, g0, g1);
            all_phase.push(PhaseMargin {
                phase_deg: wrap_deg(180.0 + l(w).arg().to_degrees()),
                gain_crossover_rad_s: w,
            });
        }
    }
    dedup(&mut all_gain, |g| g.phase_crossover_rad_s);
    dedup(&mut all_phase, |p| p.gain_crossover_rad_s);
    let gm = all_gain
        .iter()
        .min_by(|a, b| a.gain_db.abs().total_cmp(&b.gain_db.abs()));
    let pm = all_phase
        .iter()
        .min_by(|a, b| a.phase_deg.abs().total_cmp(&b.phase_deg.abs()));
    Margins {
        gain_db: gm.map(|g| g.gain_db),
        phase_crossover_rad_s: gm.map(|g| g.phase_crossover_rad_s),
        phase_deg: pm.map(|p| p.phase_deg),
        gain_crossover_rad_s: pm.map(|p| p.gain_crossover_rad_s),
        all_gain,
        all_phase,
    }
}

fn at_zero(l: &dyn Fn(f64) -> Complex<f64>) -> Option<GainMargin> {
    let l0 = l(0.0);
    (l0.re.is_finite() && l0.re < 0.0 && l0.im.abs() <= 1e-12 * l0.re.abs()).then(|| GainMargin {
        gain_db: -20.0 * l0.norm().log10(),
        phase_crossover_rad_s: 0.0,
    })
}

/// Angle wrapped into `(-180, 180]` degrees.
pub fn wrap_deg(a: f64) -> f64 {
    let r = a - 360.0 * (a / 360.0).round();
    if r <= -180.0 {
        r + 360.0
    } else {
        r
    }
}

fn dedup<T>(v: &mut Vec<T>, w: impl Fn(&T) -> f64) {
    v.dedup_by(|b, a| (w(a) - w(b)).abs() <= 1e-9 * w(a).abs().max(1e-12));
}

/// A root of `f` in `[a, b]` with `f(a) = fa`, `f(b) = fb` of opposite signs (Illinois).
pub fn refine(f: &dyn Fn(f64) -> f64, mut a: f64, mut b: f64, mut fa: f64, mut fb: f64) -> f64 {
    if fb == 0.0 {
        return b;
    }
    let mut side = 0;
    for _ in 0..200 {
        let c = (a * fb - b * fa) / (fb - fa);
        let c = if c.is_finite() && c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        if fc == 0.0 || (b - a).abs() <= 1e-12 * c.abs() {
            return c;
        }
        if fc.signum() == fb.signum() {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}
