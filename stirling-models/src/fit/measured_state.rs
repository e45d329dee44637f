//! What the record says about the model's state: the sensor offsets, the measured channels matched
//! to the model's states, and a model state estimated from the smoothed record (the free run's and
//! the multiple shooting's initial states; see [`crate::fit::free_run`] for the rules).

use serde::Serialize;
use stirling_dsl::{Model, StateKind};

use super::static_shift::cold_weight;
use super::FitError;
use crate::data::Measured;
use crate::layout::StateLayout;
use crate::signal::savitzky_golay;

/// Additive sensor offsets: measured = model + offset.
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct SensorOffsets {
    pub x: f64,
    pub y: f64,
    pub p: f64,
    /// `None` when the record has no `p_hot` or the model a single control volume.
    pub p_hot: Option<f64>,
    /// The measured CVs outside the working gas: `(sensor, offset)`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<(String, f64)>,
}

impl SensorOffsets {
    /// The offset of a channel.
    pub fn get(&self, channel: &str) -> f64 {
        match channel {
            "x" => self.x,
            "y" => self.y,
            "p" => self.p,
            "p_hot" => self.p_hot.unwrap_or(0.0),
            other => self
                .others
                .iter()
                .find(|(n, _)| n == other)
                .map_or(0.0, |(_, v)| *v),
        }
    }
}

/// A measured channel and the model state it observes.
#[derive(Clone, Debug)]
pub struct Channel {
    pub name: String,
    pub state: usize,
    pub data: Vec<f64>,
}

/// The observed channels: `x`, `y` (body positions), `p` (cold pressure), `p_hot` (hot
/// pressure, when measured and the working gas has more than one control volume), then the
/// sensors on the CVs outside the working gas.
pub fn channels(model: &dyn Model, data: &Measured) -> Result<Vec<Channel>, FitError> {
    let layout = StateLayout::working_gas(model);
    let (pos, ps) = (&layout.positions, &layout.pressures);
    let (Some(x), Some(y), Some(p)) = (&data.x, &data.y, &data.p) else {
        return Err(FitError::MissingColumns {
            file: data.source.clone(),
            stage: "the free run",
        });
    };
    if pos.len() != 2 || ps.is_empty() {
        return Err(FitError::Bodies {
            stage: "the free run",
            model: model.name().into(),
            found: pos.len(),
        });
    }
    let mut out = vec![
        Channel {
            name: "x".into(),
            state: pos[0],
            data: x.clone(),
        },
        Channel {
            name: "y".into(),
            state: pos[1],
            data: y.clone(),
        },
        Channel {
            name: "p".into(),
            state: *ps.last().expect("CVs"),
            data: p.clone(),
        },
    ];
    if let (Some(ph), true) = (&data.p_hot, ps.len() > 1) {
        out.push(Channel {
            name: "p_hot".into(),
            state: ps[0],
            data: ph.clone(),
        });
    }
    for o in super::supported::outside_channels(model, &layout, data)? {
        out.push(Channel {
            name: o.name,
            state: o.state,
            data: o.data,
        });
    }
    Ok(out)
}

/// The model state at sample `k` from the measurements (see the module doc); `h` is the
/// half-width of the smoothing window in samples.
pub fn measured_state(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
    off: &SensorOffsets,
    k: usize,
    h: usize,
) -> Result<Vec<f64>, FitError> {
    let ch = channels(model, data)?;
    let dt = data.dt();
    let n = model.n_states();
    let mut x = vec![0.0; n];
    model.equilibrium_guess(p, &mut x);
    let eq = x.clone();
    let states = model.states();
    // smooth locally: a window around k is enough
    let lo = k.saturating_sub(4 * h + 2);
    let hi = (k + 4 * h + 2).min(data.t.len() - 1);
    let smooth = |v: &[f64], hh: usize| {
        let (a, b) = savitzky_golay(&v[lo..=hi], dt, hh, 4);
        (a[k - lo], b[k - lo])
    };
    for c in &ch[..2] {
        let (v, d) = smooth(&c.data, h);
        x[c.state] = v - off.get(&c.name);
        // the velocity state follows its position state
        let vel = StateLayout::velocity_of(model, c.state).ok_or_else(|| FitError::NoVelocity {
            model: model.name().into(),
            position: states[c.state].name.clone(),
        })?;
        x[vel] = d;
    }
    let layout = StateLayout::working_gas(model);
    let ps = &layout.pressures;
    let hot = ch.iter().find(|c| c.name == "p_hot");
    let have_hot = hot.is_some();
    let pc = smooth(&ch[2].data, (h / 2).max(3)).0 - off.p;
    let ph = match hot {
        Some(c) => smooth(&c.data, (h / 2).max(3)).0 - off.get("p_hot"),
        None => 0.0,
    };
    for (i, &s) in ps.iter().enumerate() {
        let wc = cold_weight(i, ps.len(), have_hot);
        x[s] = wc * pc + (1.0 - wc) * ph;
    }
    for c in ch.iter().filter(|c| layout.outside.contains(&c.state)) {
        x[c.state] = smooth(&c.data, (h / 2).max(3)).0 - off.get(&c.name);
    }
    mass_states(model, p, &layout, &eq, &mut x);
    Ok(x)
}

/// The mass states of `x` (if any): the equilibrium total shared in proportion to `p V / T`
/// of each linked CV at the pressures already set in `x` (a CV matched to its mass state by
/// its vessel element, so a CV without one - outside the working gas - takes no share).
pub(super) fn mass_states(
    model: &dyn Model,
    p: &[f64],
    layout: &StateLayout,
    eq: &[f64],
    x: &mut [f64],
) {
    let masses = &layout.masses;
    if masses.is_empty() {
        return;
    }
    let states = model.states();
    let nv = model.vessel_names().len();
    let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
    model.pv(p, x, &mut pr, &mut vol);
    let mut t_rest = vec![0.0; nv];
    model.temperatures(p, eq, &mut t_rest);
    let element = |i: usize| match states[i].kind {
        StateKind::Mass(k) | StateKind::Pressure(k) => k,
        _ => usize::MAX,
    };
    let pressure_of = |k: usize| layout.pressures.iter().find(|&&s| element(s) == k);
    let total: f64 = masses.iter().map(|&i| eq[i]).sum();
    let share: Vec<f64> = masses
        .iter()
        .map(|&mi| {
            let k = element(mi);
            pressure_of(k).map_or(0.0, |&s| x[s] * vol[k] / t_rest[k])
        })
        .collect();
    let ssum: f64 = share.iter().sum();
    for (j, &mi) in masses.iter().enumerate() {
        x[mi] = total * share[j] / ssum;
    }
}
