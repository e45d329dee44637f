//! The multiple-shooting problem's setup: the segments of the training block and the
//! variables (free parameters, sensor offsets, every segment's initial state).

use stirling_dsl::{Model, Observation, StateKind};

use super::super::free_run::{measured_state, SensorOffsets};
use super::super::outputs::Output;
use super::super::FitError;
use super::problem::Var;
use crate::data::Measured;
use crate::signal::noise_sigma;

/// Cut `[a, b]` into segments of about `opts.cycles` cycles of the measured frequency.
pub(super) fn cut_segments(
    ch: &[Output],
    (a, b): (usize, usize),
    dt: f64,
    block: (f64, f64),
    cycles: f64,
) -> Result<Vec<(usize, usize)>, FitError> {
    let f = crate::signal::cycle_frequency(&ch[0].data[a..=b], dt)
        .or_else(|| crate::signal::cycle_frequency(&ch[1].data[a..=b], dt))
        .ok_or_else(|| FitError::BlockCycles {
            stage: "multiple shooting".into(),
            from: block.0,
            to: block.1,
        })?;
    let seg_len = ((cycles / f / dt).round() as usize).max(10);
    let nseg = ((b - a) as f64 / seg_len as f64).round().max(1.0) as usize;
    Ok((0..nseg)
        .map(|s| (a + s * (b - a) / nseg, a + (s + 1) * (b - a) / nseg))
        .collect())
}

/// The free model parameters as variables, scaled by their starting values.
pub(super) fn param_vars(model: &dyn Model, p0: &[f64], free: &[usize]) -> Vec<Var> {
    free.iter()
        .map(|&j| Var {
            name: model.params()[j].name.into(),
            initial: p0[j],
            scale: p0[j].abs().max(1e-12),
        })
        .collect()
}

/// One measured output of the problem: its channel, noise level and offset variable.
pub(super) struct Out {
    pub(super) name: String,
    pub(super) obs: Observation,
    pub(super) data: Vec<f64>,
    /// Noise standard deviation (the residuals' weight).
    pub(super) sigma: f64,
    /// The offset's variable (among the offsets), when fitted.
    pub(super) offset: Option<usize>,
}

/// What [`output_vars`] builds: the outputs, their given offsets, how many offsets are fitted.
pub(super) struct Outputs {
    pub(super) outs: Vec<Out>,
    pub(super) off0: Vec<f64>,
    pub(super) n_off: usize,
}

/// The noise level's floor and the offset's scale of an output: a pressure state's from the
/// state's scale, a position's fixed, an expression's from the spread of its record.
fn output_scales(o: &Output, sscale: &[f64]) -> (f64, f64) {
    let is_p = o.name.starts_with('p');
    match o.obs.as_state() {
        Some(s) if is_p => (1e-6 * sscale[s], 100.0),
        Some(_) => (1e-9, 1e-3),
        None => {
            let (lo, hi) = o
                .data
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                    (a.min(v), b.max(v))
                });
            let spread = (hi - lo).max(f64::MIN_POSITIVE);
            (1e-6 * spread, 1e-2 * spread)
        }
    }
}

/// The measured outputs with their noise levels; with `fit_offsets`, one offset variable each.
pub(super) fn output_vars(
    outputs: &[Output],
    off: &SensorOffsets,
    sscale: &[f64],
    fit_offsets: bool,
    vars: &mut Vec<Var>,
) -> Outputs {
    let mut outs = Vec::new();
    let mut off0 = Vec::new();
    let mut n_off = 0;
    for o in outputs {
        let given = off.get(&o.name);
        let (floor, scale) = output_scales(o, sscale);
        let offset = fit_offsets.then(|| {
            vars.push(Var {
                name: format!("{}_offset", o.name),
                initial: given,
                scale,
            });
            n_off += 1;
            n_off - 1
        });
        outs.push(Out {
            name: o.name.clone(),
            obs: o.obs.clone(),
            data: o.data.clone(),
            sigma: noise_sigma(&o.data).max(floor),
            offset,
        });
        off0.push(given);
    }
    Outputs { outs, off0, n_off }
}

/// Every segment's initial state as variables, started from the smoothed measurements.
pub(super) fn segment_vars(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    off: &SensorOffsets,
    segs: &[(usize, usize)],
    (h, sscale): (usize, &[f64]),
    vars: &mut Vec<Var>,
) -> Result<(), FitError> {
    let n = model.n_states();
    let names = model.state_names();
    let states = model.states();
    for (s, &(sa, _)) in segs.iter().enumerate() {
        let x0 = measured_state(model, p0, data, off, sa, h)?;
        for i in 0..n {
            let scale = match states[i].kind {
                StateKind::Position(_) => 1e-3,
                StateKind::Velocity(_) => 0.05,
                StateKind::Pressure(_) | StateKind::Mass(_) | StateKind::WallTemperature(_) => {
                    0.01 * sscale[i]
                }
            };
            vars.push(Var {
                name: format!("seg{s}.{}", names[i]),
                initial: x0[i],
                scale,
            });
        }
    }
    Ok(())
}
