//! Stage 1: the mechanics (both bodies) driven by the pressures on their faces.
//!
//! Every CV pressure the bodies feel is prescribed: the cold side from the measured `p`, the hot
//! side from `p_hot` when it is measured (sections in between interpolated linearly), and otherwise
//! from the measured `p` plus the pressure differences `P_i - P_cold` that the gas stage computes
//! from the measured positions ([`crate::fit::unmeasured`]); a CV outside the working gas (a closed
//! bounce space) from its own sensor. Fitted: the free mechanical parameters, the initial body
//! states and the position offsets (which also absorb the static shift of a pressure offset).

use stirling_dsl::Model;

use super::driven::Stage;
use super::record::Record;
use super::sensitivity::{Given, Signal};
use super::static_shift::cold_weight;
use super::vars::{Output, Var};
use super::{FitError, FitOptions};
use crate::layout::StateLayout;
use crate::signal::{cycle_frequency, drift_count, noise_sigma};

/// What stage 1 is built from besides the record.
pub struct MechInputs<'s> {
    /// Current parameters and the free mechanical ones (indices).
    pub p: &'s [f64],
    pub free: &'s [usize],
    /// Position offsets to start from.
    pub x_off: [f64; 2],
    /// Pressure offsets subtracted from the measured `p` and `p_hot`.
    pub p_off: f64,
    pub ph_off: f64,
    /// Model pressure differences `P_i - P_cold`, one per CV (in [`StateLayout::pressures`]
    /// order), when the hot side is not measured; `None`: prescribe from the measurements.
    pub dp: Option<&'s [Signal]>,
    /// Offsets of the measured CVs outside the working gas ([`Record::outside`] order).
    pub out_off: &'s [f64],
}

/// The pressures of the CVs outside the working gas, prescribed from their own sensors
/// (signals `first..`).
fn given_outside(rec: &Record, out_off: &[f64], first: usize) -> Vec<Given> {
    rec.outside
        .iter()
        .zip(out_off)
        .enumerate()
        .map(|(k, (o, off))| Given {
            state: o.state,
            terms: vec![(first + k, 1.0, false)],
            constant: -off,
        })
        .collect()
}

/// The CV pressures prescribed from `p` plus the gas stage's differences `dp` (pushed onto
/// `signals`).
fn given_with_dp(ps: &[usize], dp: &[Signal], p_off: f64, signals: &mut Vec<Signal>) -> Vec<Given> {
    let cold = ps.len() - 1;
    ps.iter()
        .enumerate()
        .map(|(i, &s)| {
            let mut terms = vec![(0, 1.0, false)];
            if i != cold {
                terms.push((signals.len(), 1.0, false));
                signals.push(dp[i].clone());
            }
            Given {
                state: s,
                terms,
                constant: -p_off,
            }
        })
        .collect()
}

/// The CV pressures prescribed from the measured `p` (and `p_hot`), interpolated between.
fn given_measured(ps: &[usize], inp: &MechInputs, have_hot: bool) -> Vec<Given> {
    ps.iter()
        .enumerate()
        .map(|(i, &s)| {
            let wc = cold_weight(i, ps.len(), have_hot);
            let mut terms = vec![(0, wc, false)];
            if have_hot {
                terms.push((1, 1.0 - wc, false));
            }
            let hot = if have_hot {
                (1.0 - wc) * inp.ph_off
            } else {
                0.0
            };
            Given {
                state: s,
                terms,
                constant: -wc * inp.p_off - hot,
            }
        })
        .collect()
}

/// The cycle frequency on the training block `tr` (from `y`, else `x`; 0 if neither cycles).
fn training_frequency(xm: &[f64], ym: &[f64], tr: (usize, usize), dt: f64) -> f64 {
    cycle_frequency(&ym[tr.0..=tr.1], dt)
        .or_else(|| cycle_frequency(&xm[tr.0..=tr.1], dt))
        .unwrap_or(0.0)
}

/// The body states `[x, v, y, w]` at the window start from the smoothed measured positions.
fn body_start(rec: &Record, x_off: [f64; 2]) -> Vec<f64> {
    let (sx, sy) = rec.pos.as_ref().expect("checked");
    let ta = rec.tr.0;
    vec![
        sx.val[ta] - x_off[0],
        sx.der[ta],
        sy.val[ta] - x_off[1],
        sy.der[ta],
    ]
}

/// Restarts of stage 1 from the measured body states every `cycles` cycles of frequency `f0`
/// (`None` without them, or without a cycle).
fn restarts(
    rec: &Record,
    x_off: [f64; 2],
    cycles: Option<f64>,
    f0: f64,
) -> Option<super::restarts::Restarts> {
    let every = (cycles? / (f0 * rec.dt)).round();
    if !every.is_finite() || every < MIN_SEGMENT {
        return None;
    }
    let (sx, sy) = rec.pos.as_ref()?;
    let states = (0..sx.val.len())
        .map(|k| {
            vec![
                sx.val[k] - x_off[0],
                sx.der[k],
                sy.val[k] - x_off[1],
                sy.der[k],
            ]
        })
        .collect();
    Some(super::restarts::Restarts {
        every: every as usize,
        states,
        channels: vec!["x", "x", "y", "y"],
    })
}

/// The fewest samples of a restarted segment: shorter ones see the smoothed start more than
/// the model.
const MIN_SEGMENT: f64 = 8.0;

/// The fit variables: free parameters, the four body initial states `z0`, the position offsets.
fn variables(model: &dyn Model, inp: &MechInputs, z0: &[f64], opts: &FitOptions) -> Vec<Var> {
    let x_off = inp.x_off;
    let mut vars = Var::params(model, inp.p, inp.free, opts);
    for (k, nm) in ["x(0)", "v(0)", "y(0)", "w(0)"].iter().enumerate() {
        vars.push(Var::initial(
            nm,
            z0[k],
            if k % 2 == 0 { 1e-3 } else { 0.05 },
            k,
        ));
    }
    vars.push(Var::offset("x_offset", x_off[0], 1e-3, 0, vec![]));
    vars.push(Var::offset("y_offset", x_off[1], 1e-3, 1, vec![]));
    vars
}

/// The noise on the prescribed pressure signals: `(signal, sigma, smoothing half-width)`.
fn input_noise(rec: &Record) -> Vec<(usize, f64, usize)> {
    let data = rec.data;
    let hp = (rec.h / 2).max(3);
    let mut input_noise = vec![(0, noise_sigma(data.p.as_ref().expect("checked")), hp)];
    if let Some(v) = data.p_hot.as_ref().filter(|_| rec.have_hot) {
        input_noise.push((1, noise_sigma(v), hp));
    }
    let first = input_noise.len();
    for (k, o) in rec.outside.iter().enumerate() {
        input_noise.push((first + k, noise_sigma(&o.raw), hp));
    }
    input_noise
}

/// Build stage 1.
pub fn stage<'a>(
    model: &'a dyn Model,
    layout: &StateLayout,
    rec: &Record,
    inp: &MechInputs,
    opts: &FitOptions,
) -> Result<Stage<'a>, FitError> {
    let data = rec.data;
    let (Some(xm), Some(ym), Some(sp)) = (data.x.as_ref(), data.y.as_ref(), rec.sig_p.as_ref())
    else {
        return Err(FitError::MissingColumns {
            file: data.source.clone(),
            stage: "stage 1 (mechanics)",
        });
    };
    if layout.positions.len() != 2 {
        return Err(FitError::Bodies {
            stage: "stage 1",
            model: model.name().into(),
            found: layout.positions.len(),
        });
    }
    let have_hot = rec.have_hot;
    let mut signals = vec![sp.clone()];
    if have_hot {
        signals.push(rec.sig_ph.clone().expect("have_hot"));
    }
    let first_outside = signals.len();
    signals.extend(rec.outside.iter().map(|o| o.sig.clone()));
    let measured = signals.len();
    let ps = &layout.pressures;
    let mut given: Vec<Given> = match inp.dp {
        Some(dp) => given_with_dp(ps, dp, inp.p_off, &mut signals),
        None => given_measured(ps, inp, have_hot),
    };
    given.extend(given_outside(rec, inp.out_off, first_outside));
    let z0 = body_start(rec, inp.x_off);
    let vars = variables(model, inp, &z0, opts);
    let outputs = vec![Output::new("x", 0, xm, 1e-9), Output::new("y", 2, ym, 1e-9)];
    let (tr, dt) = (rec.tr, rec.dt);
    let f0 = training_frequency(xm, ym, tr, dt);
    let mut base = vec![0.0; model.n_states()];
    model.equilibrium_guess(inp.p, &mut base);
    Ok(Stage {
        drift: drift_count(tr.1 - tr.0 + 1, dt, opts.drift_cut * f0),
        input_noise: input_noise(rec),
        derived: (measured..signals.len()).collect(),
        restarts: restarts(rec, inp.x_off, opts.restart_cycles, f0),
        name: "stage 1 (mechanics driven by measured pressure)",
        model,
        p: inp.p.to_vec(),
        base,
        free: layout.bodies.clone(),
        given,
        signals,
        z0,
        vars,
        outputs,
        t0: rec.t0,
        dt,
        sim: opts.sim,
    })
}
