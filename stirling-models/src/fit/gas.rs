//! Stage 2: the gas driven by the measured displacements.
//!
//! The body states are prescribed from the measured positions (offsets removed) and their smoothed
//! derivatives; fitted: the free gas parameters and the pressure offsets. A pressure offset moves
//! the position offsets stage 1 found by the static response `-J_qq^-1 J_qP off`
//! ([`static_shift`](crate::fit::static_shift::static_shift)), so the prescribed positions depend
//! on it and its sensitivity column carries that input term.

use stirling_dsl::Model;

use super::driven::Stage;
use super::record::Record;
use super::sensitivity::Given;
use super::static_shift::{cold_weight, static_shift};
use super::vars::{Output, Var};
use super::{FitError, FitOptions};
use crate::layout::StateLayout;
use crate::signal::noise_sigma;

/// Stage 2 with the bookkeeping that turns its pressure offsets back into position offsets.
pub struct GasStage<'a> {
    pub stage: Stage<'a>,
    /// Static position shift per unit offset of `p` (`[0]`), `p_hot` (`[1]`) and each
    /// measured CV outside the working gas (`[2..]`), `[x, y]`.
    pub shift: Vec<Vec<f64>>,
    /// The shift that the pressure offsets used in stage 1 caused, `[x, y]`.
    pub used: [f64; 2],
    /// Samples skipped at the window start while the gas forgets its initial state.
    pub burn: usize,
}

impl GasStage<'_> {
    /// Position offsets seen by the free model after stage 2 found the pressure offsets
    /// `offs` (channels as [`GasStage::shift`]).
    pub fn position_offsets(&self, x_off: [f64; 2], offs: &[f64]) -> [f64; 2] {
        let s = &self.shift;
        // summed from `x_off` channel by channel: the family's values bit for bit as before
        [0, 1].map(|k| s.iter().zip(offs).fold(x_off[k], |a, (c, o)| a + c[k] * o) - self.used[k])
    }
}

/// The pressure offsets a record starts from, channels as [`GasStage::shift`].
pub fn first_offsets(rec: &Record) -> Vec<f64> {
    let mut v = vec![rec.p_off0, rec.ph_off0];
    v.extend(rec.outside.iter().chain(&rec.inside).map(|o| o.off0));
    v
}

/// Build stage 2 at parameters `p` (free gas parameters `free`), with the position offsets
/// `x_off` stage 1 found under the pressure offsets `rec.p_off0`, `rec.ph_off0`.
pub fn stage<'a>(
    model: &'a dyn Model,
    layout: &StateLayout,
    rec: &Record,
    p: &[f64],
    free: &[usize],
    x_off: [f64; 2],
    opts: &FitOptions,
) -> Result<GasStage<'a>, FitError> {
    let data = rec.data;
    let (Some(xm), Some(ym), Some(_)) = (data.x.as_ref(), data.y.as_ref(), data.p.as_ref()) else {
        return Err(FitError::MissingColumns {
            file: data.source.clone(),
            stage: "stage 2 (gas)",
        });
    };
    let have_hot = rec.have_hot;
    let off0 = first_offsets(rec);
    let mut eq = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut eq);
    let shift = static_shift(model, p, have_hot)?;
    let (sx, sy) = rec.pos.clone().expect("checked");
    let used = [0, 1].map(|k| {
        let mut terms = shift.iter().zip(&off0).map(|(c, o)| c[k] * o);
        let first = terms.next().unwrap_or(0.0);
        terms.fold(first, |a, t| a + t)
    });
    let given = given_bodies(layout, x_off, used);
    let mut vars = Var::params(model, p, free, opts);
    let outputs = pressure_outputs(layout, rec, &eq, &shift, &mut vars);
    let x_start = initial_state(model, layout, rec, p, &eq, x_off);
    // the gas stage integrates the walls with a heat capacity too (after the gas states, so
    // the gas positions stay those of `layout.gas`): a wall is driven by the gas it touches
    let free: Vec<usize> = layout.gas.iter().chain(&layout.walls).copied().collect();
    let z0: Vec<f64> = free.iter().map(|&i| x_start[i]).collect();
    // a closed CV keeps its gas: its mean pressure is set by its temperature, which relaxes
    // over seconds (no burn-in forgets it), so its initial pressure is fitted, as stage 1
    // fits the bodies' initial states - else its offset would absorb the transient
    let names = model.state_names();
    for o in &rec.outside {
        let pos = free
            .iter()
            .position(|&i| i == o.state)
            .expect("a gas state");
        vars.push(Var::initial(
            &format!("{}(0)", names[o.state]),
            z0[pos],
            100.0,
            pos,
        ));
    }
    let (tr, dt) = (rec.tr, rec.dt);
    let burn = ((opts.burn_in / dt).round() as usize).min(tr.1 - tr.0 - 5);
    let stage = Stage {
        drift: 0,
        input_noise: vec![(0, noise_sigma(xm), rec.h), (1, noise_sigma(ym), rec.h)],
        derived: Vec::new(),
        restarts: None,
        name: "stage 2 (gas driven by measured displacements)",
        model,
        p: p.to_vec(),
        base: eq,
        free,
        given,
        signals: vec![sx, sy],
        z0,
        vars,
        outputs,
        t0: rec.t0,
        dt,
        sim: opts.sim,
    };
    Ok(GasStage {
        stage,
        shift,
        used,
        burn,
    })
}

/// The body states prescribed from the measured positions (offsets `x_off` less the static
/// shift `used`) and their derivatives.
fn given_bodies(layout: &StateLayout, x_off: [f64; 2], used: [f64; 2]) -> Vec<Given> {
    let (pos, vel) = (&layout.positions, &layout.velocities);
    vec![
        Given::signal(pos[0], 0, false, -x_off[0] + used[0]),
        Given::signal(vel[0], 0, true, 0.0),
        Given::signal(pos[1], 1, false, -x_off[1] + used[1]),
        Given::signal(vel[1], 1, true, 0.0),
    ]
}

/// The measured pressure outputs, pushing their offset variables (whose input term is the
/// static `shift`) onto `vars`.
fn pressure_outputs(
    layout: &StateLayout,
    rec: &Record,
    eq: &[f64],
    shift: &[Vec<f64>],
    vars: &mut Vec<Var>,
) -> Vec<Output> {
    let data = rec.data;
    let pm = data.p.as_ref().expect("checked");
    let du = |ch: usize| vec![-shift[ch][0], 0.0, -shift[ch][1], 0.0];
    let ps = &layout.pressures;
    let pmean = ps.first().map(|&i| eq[i]).unwrap_or(0.0);
    let cold_pos = layout.gas_pos(*ps.last().expect("CVs")).expect("gas state");
    let hot_pos = layout.gas_pos(ps[0]).expect("gas state");
    vars.push(Var::offset("p_offset", rec.p_off0, 100.0, 0, du(0)));
    let mut outputs = vec![Output::new("p", cold_pos, pm, 1e-6 * pmean)];
    if rec.have_hot {
        let ph = data.p_hot.as_ref().expect("have_hot");
        vars.push(Var::offset("p_hot_offset", rec.ph_off0, 100.0, 1, du(1)));
        outputs.push(Output::new("p_hot", hot_pos, ph, 1e-6 * pmean));
    }
    for (k, o) in rec.outside.iter().enumerate() {
        let name = format!("{}_offset", o.name);
        vars.push(Var::offset(&name, o.off0, 100.0, outputs.len(), du(2 + k)));
        let at = layout.gas_pos(o.state).expect("gas state");
        outputs.push(Output::new(&o.name, at, &o.raw, 1e-6 * pmean));
    }
    // a sensor inside the working gas: an output only (the bodies are not driven by it, so
    // its offset shifts no position)
    for o in &rec.inside {
        let name = format!("{}_offset", o.name);
        vars.push(Var::offset(
            &name,
            o.off0,
            100.0,
            outputs.len(),
            vec![0.0; 4],
        ));
        let at = layout.gas_pos(o.state).expect("gas state");
        outputs.push(Output::new(&o.name, at, &o.raw, 1e-6 * pmean));
    }
    outputs
}

/// The initial gas state at the window start: measured pressures, masses sharing the
/// model's inventory in proportion to `P V / T_rest`.
fn initial_state(
    model: &dyn Model,
    layout: &StateLayout,
    rec: &Record,
    p: &[f64],
    eq: &[f64],
    x_off: [f64; 2],
) -> Vec<f64> {
    let (sx, sy) = rec.pos.as_ref().expect("checked");
    let sp = rec.sig_p.as_ref().expect("checked");
    let mut x = eq.to_vec();
    let ta = rec.tr.0;
    let (pos, vel) = (&layout.positions, &layout.velocities);
    x[pos[0]] = sx.val[ta] - x_off[0];
    x[vel[0]] = sx.der[ta];
    x[pos[1]] = sy.val[ta] - x_off[1];
    x[vel[1]] = sy.der[ta];
    let ps = &layout.pressures;
    let ncv = ps.len();
    let hot = rec
        .sig_ph
        .as_ref()
        .filter(|_| rec.have_hot)
        .map(|s| s.val[ta] - rec.ph_off0)
        .unwrap_or(0.0);
    for (i, &s) in ps.iter().enumerate() {
        let wc = cold_weight(i, ncv, rec.have_hot);
        x[s] = wc * (sp.val[ta] - rec.p_off0) + (1.0 - wc) * hot;
    }
    for o in rec.outside.iter().chain(&rec.inside) {
        x[o.state] = o.sig.val[ta] - o.off0;
    }
    super::measured_state::mass_states(model, p, layout, eq, &mut x);
    x
}
