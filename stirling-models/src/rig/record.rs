//! The record a rig run gives: the clean run of the truth model, and what the sensors of the
//! asked channels read of it (the seed's four where the family has them, any other declared
//! sensor of the model).

use stirling_dsl::{Model, Observation};

use super::sensors::{self, read_sensors};
use super::{RigConfig, RigError};
use crate::data::Measured;
use crate::effects::EffectSettings;
use crate::layout::StateLayout;
use crate::sim::{simulate, SimOptions};

/// The clean run: from equilibrium with the first state (the displacer) kicked by `x0` and the
/// states `start` names set (a flywheel pushed), sampled at `rate` after `settle` (rows: the
/// `count + 1` samples).
fn clean_run(
    model: &dyn Model,
    p: &[f64],
    cfg: &RigConfig,
    count: usize,
) -> Result<Vec<Vec<f64>>, RigError> {
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x0);
    x0[0] += cfg.x0;
    let names = model.state_names();
    for (name, v) in &cfg.start {
        let Some(i) = names.iter().position(|n| n == name) else {
            return Err(RigError::UnknownState {
                state: name.clone(),
                model: model.name().into(),
                known: names.join(", "),
            });
        };
        x0[i] = *v;
    }
    let dt = 1.0 / cfg.rate;
    let samples: Vec<f64> = (0..=count).map(|k| cfg.settle + k as f64 * dt).collect();
    let opts = SimOptions {
        rtol: 1e-8,
        atol: 1e-8,
        ..Default::default()
    };
    let traj = simulate(
        model,
        p,
        &x0,
        cfg.settle + count as f64 * dt,
        &samples,
        &opts,
    )?;
    Ok(traj.x)
}

/// The record the sensors of `cfg.channels` give of a clean run of `model`.
pub(super) fn record(
    model: &dyn Model,
    p: &[f64],
    fx: &EffectSettings,
    cfg: &RigConfig,
) -> Result<Measured, RigError> {
    let lay = StateLayout::working_gas(model);
    let ps = &lay.pressures;
    // the seed's channels where the model declares them, else where the family has them
    let at = |name: &str, fallback: Option<&usize>| match model.sensor_state(name) {
        Some(s) => s,
        None => fallback.copied(),
    };
    let (Some(ic), Some(ih)) = (at("p", ps.last()), at("p_hot", ps.first())) else {
        return Err(RigError::NoGas {
            model: model.name().into(),
        });
    };
    let want = |c: &str| cfg.channels.iter().any(|k| k == c);
    if want("p_hot") && ps.len() < 2 {
        return Err(RigError::NoHotSide {
            model: model.name().into(),
        });
    }
    let pos = &lay.positions;
    let mut chans = match (at("x", pos.first()), at("y", pos.get(1))) {
        (Some(a), Some(b)) => sensors::seed_channels((ic, ih, ps.len()), [a, b], fx, cfg),
        _ => Vec::new(),
    };
    for c in &cfg.channels {
        if !chans.iter().any(|k| &k.name == c) {
            chans.push(declared_channel(model, c, fx, cfg)?);
        }
    }
    let count = (cfg.t_end * cfg.rate).round() as usize;
    let dt = 1.0 / cfg.rate;
    let rows = clean_run(model, p, cfg, count)?;
    for c in &mut chans {
        if let Some(sd) = cfg.noise_of(&c.name) {
            c.sd = sd;
        }
    }
    let read = read_sensors((model, p), &rows, &chans, cfg)?;
    let mut data = Measured {
        source: format!("rig:{}", model.name()),
        t: (0..=count).map(|k| k as f64 * dt).collect(),
        ..Default::default()
    };
    for (c, v) in chans.iter().zip(read) {
        if !want(&c.name) {
            continue;
        }
        match c.name.as_str() {
            "p" => data.p = Some(v),
            "p_hot" => data.p_hot = Some(v),
            "x" => data.x = Some(v),
            "y" => data.y = Some(v),
            _ => data.others.push((c.name.clone(), v)),
        }
    }
    Ok(data)
}

/// A channel of `model`'s declared sensor `name`.
fn declared_channel(
    model: &dyn Model,
    name: &str,
    fx: &EffectSettings,
    cfg: &RigConfig,
) -> Result<sensors::Channel, RigError> {
    let known = || {
        model
            .sensors()
            .iter()
            .map(|s| s.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some(sensor) = model.sensors().iter().find(|s| s.name == name) else {
        return state_channel(model, name, cfg).ok_or_else(|| RigError::UnknownChannel {
            channel: name.into(),
            known: format!(
                "{} (the sensors `{}` declares), or one of its states",
                known(),
                model.name()
            ),
        })?;
    };
    let obs = Observation::sensor(model, name).map_err(|e| RigError::UnknownChannel {
        channel: name.into(),
        known: format!("{}; {e}", known()),
    })?;
    // an absolute pressure carries the transducer's offset and must stay positive; a
    // difference or another expression is read zeroed at rest
    let state = obs.as_state().is_some();
    let (offset, sd, pressure) = match (sensor.unit, cfg.noise_of(name)) {
        ("Pa", _) if state => (cfg.offset_p, cfg.noise_p, true),
        ("Pa", _) => (0.0, cfg.noise_p, false),
        ("m", _) => (0.0, cfg.noise_x, false),
        (_, Some(sd)) => (0.0, sd, false),
        (unit, None) => {
            return Err(RigError::SensorUnit {
                channel: name.into(),
                unit: unit.into(),
            })
        }
    };
    // its own distortions (`effect lag on sensor ..;`), else the library's lag of every
    // absolute pressure transducer
    let own = |prefix: &str| fx.sensor_set(&format!("{prefix}_{name}"));
    let tau = own("tau").unwrap_or(if pressure {
        fx.sensor_value("tau_p")
    } else {
        0.0
    });
    Ok(sensors::Channel {
        name: name.into(),
        obs,
        tau,
        gain: own("gain").unwrap_or(0.0),
        offset,
        sd,
        pressure,
    })
}

/// A channel reading state `name` directly (a flywheel's angle `theta`, as an encoder reads
/// it): no lag, gain or offset; its noise is `--noise NAME=SD`, else `noise_x` for a position
/// in m, else the state's unit must be given a level ([`RigError::SensorUnit`]). `None`: the
/// model has no such state.
fn state_channel(
    model: &dyn Model,
    name: &str,
    cfg: &RigConfig,
) -> Option<Result<sensors::Channel, RigError>> {
    let i = model.states().iter().position(|s| s.name == name)?;
    let unit = model.states()[i].unit;
    let sd = match (unit, cfg.noise_of(name)) {
        (_, Some(sd)) => sd,
        ("m", None) => cfg.noise_x,
        (unit, None) => {
            return Some(Err(RigError::SensorUnit {
                channel: name.into(),
                unit: unit.into(),
            }))
        }
    };
    Some(Ok(sensors::Channel {
        name: name.into(),
        obs: Observation::state(i),
        tau: 0.0,
        gain: 0.0,
        offset: 0.0,
        sd,
        pressure: false,
    }))
}
