//! The sensors of the rig: pressure lag, position gain errors, offsets and seeded noise.

use rand::{rngs::StdRng, Rng, SeedableRng};
use stirling_dsl::{Model, Observation};

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

/// One channel the rig writes: the model output it reads (a state, or a declared sensor's
/// expression) and what its sensor does to it.
pub(super) struct Channel {
    pub name: String,
    pub obs: Observation,
    /// First-order lag (s) and relative gain error.
    pub tau: f64,
    pub gain: f64,
    /// Additive offset and noise standard deviation, in the channel's unit.
    pub offset: f64,
    pub sd: f64,
    /// Whether the channel is an absolute pressure (checked to stay positive).
    pub pressure: bool,
}

/// The seed's channels of a family member: cold pressure `p` (state `ic`), hot pressure
/// `p_hot` (`ih`, several CVs only), `x`, `y` (the two bodies' positions `pos`), in the
/// order the rig has always drawn their noise (`p_hot` drawn even when not written, so a
/// seed gives the same record whatever channels are asked for).
pub(super) fn seed_channels(
    (ic, ih, ncv): (usize, usize, usize),
    pos: [usize; 2],
    fx: &EffectSettings,
    cfg: &RigConfig,
) -> Vec<Channel> {
    // `tau_p` lags both transducers; `tau_p_hot` (a lag named on that sensor) the hot one
    let tau = |name: &str| {
        fx.sensor_set(&format!("tau_{name}"))
            .unwrap_or_else(|| fx.sensor_value("tau_p"))
    };
    let pressure = |name: &str, state| Channel {
        name: name.into(),
        obs: Observation::state(state),
        tau: tau(name),
        gain: 0.0,
        offset: cfg.offset_p,
        sd: cfg.noise_p,
        pressure: true,
    };
    let position = |name: &str, state, gain, offset| Channel {
        name: name.into(),
        obs: Observation::state(state),
        tau: 0.0,
        gain,
        offset,
        sd: cfg.noise_x,
        pressure: false,
    };
    let mut out = vec![pressure("p", ic)];
    if ncv > 1 {
        out.push(pressure("p_hot", ih));
    }
    out.push(position(
        "x",
        pos[0],
        fx.sensor_value("gain_x"),
        cfg.offset_x,
    ));
    out.push(position(
        "y",
        pos[1],
        fx.sensor_value("gain_y"),
        cfg.offset_y,
    ));
    out
}

/// What the sensors read from the clean `rows` of `model` at `p`: per channel, lag, gain,
/// offset and seeded noise (one generator, drawn channel after channel).
pub(super) fn read_sensors(
    (model, p): (&dyn Model, &[f64]),
    rows: &[Vec<f64>],
    chans: &[Channel],
    cfg: &RigConfig,
) -> Result<Vec<Vec<f64>>, RigError> {
    let dt = 1.0 / cfg.rate;
    let mut g = Gauss(StdRng::seed_from_u64(cfg.seed));
    let mut out = Vec::with_capacity(chans.len());
    for c in chans {
        let clean: Vec<f64> = rows.iter().map(|r| c.obs.value(model, p, r)).collect();
        if let Some(k) = clean.iter().position(|v| !v.is_finite()) {
            return Err(RigError::NonFinite {
                channel: c.name.clone(),
                t: k as f64 * dt,
            });
        }
        if c.pressure {
            check_pressure(&clean, cfg)?;
        }
        let v = first_order_lag(&clean, dt, c.tau)
            .into_iter()
            .map(|s| (1.0 + c.gain) * s + c.offset + c.sd * g.next())
            .collect();
        out.push(v);
    }
    Ok(out)
}
