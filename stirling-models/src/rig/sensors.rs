//! The sensors of the rig: pressure lag, position gain errors, offsets and seeded noise.

use rand::{rngs::StdRng, Rng, SeedableRng};

use super::{RigConfig, RigError};
use crate::effects::EffectSettings;
use crate::signal::first_order_lag;

/// Gaussian samples by Box-Muller on a seeded generator.
struct Gauss(StdRng);

impl Gauss {
    fn next(&mut self) -> f64 {
        let u1: f64 = 1.0 - self.0.gen::<f64>();
        let u2: f64 = self.0.gen::<f64>();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// Refuse a record whose absolute pressure can go negative (noise or offset larger than
/// the pressure itself).
fn check_pressure(p: &[f64], cfg: &RigConfig) -> Result<(), RigError> {
    let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
    if lo + cfg.offset_p - 5.0 * cfg.noise_p <= 0.0 {
        return Err(RigError::NegativePressure {
            min: lo,
            offset: cfg.offset_p,
            noise: cfg.noise_p,
        });
    }
    Ok(())
}

/// The sensor readings of a clean run: cold and hot pressure, `x`, `y`.
pub(super) struct Readings {
    pub pc: Vec<f64>,
    pub ph: Option<Vec<f64>>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// What the sensors read from the clean `rows`: lag, gain, offset and seeded noise (cold
/// pressure state `ic`, hot `ih` when there are several CVs).
pub(super) fn read_sensors(
    rows: &[Vec<f64>],
    (ic, ih, ncv): (usize, usize, usize),
    fx: &EffectSettings,
    cfg: &RigConfig,
) -> Result<Readings, RigError> {
    let dt = 1.0 / cfg.rate;
    let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
    let tau = fx.sensor_value("tau_p");
    let (gx, gy) = (fx.sensor_value("gain_x"), fx.sensor_value("gain_y"));
    let mut g = Gauss(StdRng::seed_from_u64(cfg.seed));
    let mut noisy = |v: Vec<f64>, gain: f64, off: f64, sd: f64| {
        v.into_iter()
            .map(|s| (1.0 + gain) * s + off + sd * g.next())
            .collect::<Vec<f64>>()
    };
    let pc = noisy(
        first_order_lag(&col(ic), dt, tau),
        0.0,
        cfg.offset_p,
        cfg.noise_p,
    );
    let ph = if ncv > 1 {
        Some(noisy(
            first_order_lag(&col(ih), dt, tau),
            0.0,
            cfg.offset_p,
            cfg.noise_p,
        ))
    } else {
        None
    };
    check_pressure(&col(ic), cfg)?;
    let x = noisy(col(0), gx, cfg.offset_x, cfg.noise_x);
    let y = noisy(col(2), gy, cfg.offset_y, cfg.noise_x);
    Ok(Readings { pc, ph, x, y })
}
