//! Stage 2 of a kinematic engine: the gas driven by the measured crank angle. The flywheel's
//! angle is prescribed from the smoothed measured angle and its speed from the smoothing
//! derivative (as the free-piston engine's stage 2 prescribes the bodies from the measured
//! positions); the cranks follow the angle inside the model. Fitted: the free gas parameters
//! and the pressure offsets (an offset here moves no prescribed input: the angle does not
//! answer the pressure).

use stirling_dsl::{Model, StateKind};

use super::angle::Angle;
use crate::fit::driven::Stage;
use crate::fit::record::{signal, Record};
use crate::fit::sensitivity::Given;
use crate::fit::static_shift::cold_weight;
use crate::fit::vars::{Output, Var};
use crate::fit::{FitError, FitOptions};
use crate::layout::StateLayout;
use crate::signal::noise_sigma;

/// Stage 2 of a kinematic engine at parameters `p` (free gas parameters `free`), and the
/// samples skipped at the window start while the gas forgets its initial state.
pub fn stage<'a>(
    model: &'a dyn Model,
    layout: &StateLayout,
    rec: &Record,
    angle: &Angle,
    p: &[f64],
    free: &[usize],
    opts: &FitOptions,
) -> Result<(Stage<'a>, usize), FitError> {
    let mut eq = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut eq);
    let sig = signal(rec.t0, rec.dt, &angle.data, rec.h);
    let given = vec![
        Given::signal(angle.angle, 0, false, 0.0),
        Given::signal(angle.speed, 0, true, 0.0),
    ];
    let mut vars = Var::params(model, p, free, opts);
    let outputs = outputs(layout, rec, &eq, &mut vars);
    let mut x = eq.clone();
    let ta = rec.tr.0;
    x[angle.angle] = sig.val[ta];
    x[angle.speed] = sig.der[ta];
    initial_gas(model, layout, rec, p, &eq, &mut x);
    let free: Vec<usize> = layout.gas.iter().chain(&layout.walls).copied().collect();
    let z0: Vec<f64> = free.iter().map(|&i| x[i]).collect();
    // a closed CV's initial pressure is fitted (its mean relaxes over seconds), as in the
    // free-piston engine's stage 2
    let names = model.state_names();
    for o in &rec.outside {
        let pos = free.iter().position(|&i| i == o.state).expect("gas state");
        let name = format!("{}(0)", names[o.state]);
        vars.push(Var::initial(&name, z0[pos], 100.0, pos));
    }
    // the gas's initial masses: a leak sets the inventory while the engine runs (the cycle's
    // mean pressure settles at the room's), and the gas temperatures at the window start are
    // not the rest state's; the inventory relaxes over seconds and the temperatures over
    // several burn-ins (a 0.2 s burn-in left the gamma LTD's fit at 91 % on a noise-free
    // record, with hs 34 % off), so each CV's mass at the window start is fitted
    for &m in &layout.masses {
        let pos = free.iter().position(|&i| i == m).expect("gas state");
        let name = format!("{}(0)", names[m]);
        vars.push(Var::initial(&name, z0[pos], 1e-3 * z0[pos].abs(), pos));
    }
    // a wall with a heat capacity (`heater_input` on a port) starts the window at a
    // temperature the record does not show: fitted like the masses (the gamma LTD with a 1
    // J/K hot plate, its capacity held at the truth: `p` fitted to 85 % from the rest
    // state's wall temperature, 97.6 % with it fitted, `hp` and `hs` then at the truth)
    for &w in &layout.walls {
        let pos = free.iter().position(|&i| i == w).expect("wall state");
        let name = format!("{}(0)", names[w]);
        vars.push(Var::initial(&name, z0[pos], 1.0, pos));
    }
    let (tr, dt) = (rec.tr, rec.dt);
    let burn = ((opts.burn_in / dt).round() as usize).min(tr.1 - tr.0 - 5);
    let stage = Stage {
        name: "stage 2 (gas driven by the measured crank angle)",
        model,
        p: p.to_vec(),
        base: eq,
        free,
        given,
        signals: vec![sig],
        z0,
        vars,
        outputs,
        t0: rec.t0,
        dt,
        sim: opts.sim,
        drift: 0,
        input_noise: vec![(0, noise_sigma(&angle.data), rec.h)],
        derived: Vec::new(),
        restarts: None,
    };
    Ok((stage, burn))
}

/// The measured pressures as outputs (`p`, `p_hot` when measured, the CVs outside the working
/// gas, the sensors inside it), each with its offset variable pushed onto `vars`.
fn outputs(layout: &StateLayout, rec: &Record, eq: &[f64], vars: &mut Vec<Var>) -> Vec<Output> {
    let data = rec.data;
    let ps = &layout.pressures;
    let pmean = ps.first().map(|&i| eq[i]).unwrap_or(0.0);
    let at = |state: usize| layout.gas_pos(state).expect("gas state");
    let pm = data.p.as_ref().expect("checked");
    let mut outputs = vec![Output::new(
        "p",
        at(*ps.last().expect("CVs")),
        pm,
        1e-6 * pmean,
    )];
    vars.push(Var::offset("p_offset", rec.p_off0, 100.0, 0, Vec::new()));
    if rec.have_hot {
        let ph = data.p_hot.as_ref().expect("have_hot");
        vars.push(Var::offset(
            "p_hot_offset",
            rec.ph_off0,
            100.0,
            1,
            Vec::new(),
        ));
        outputs.push(Output::new("p_hot", at(ps[0]), ph, 1e-6 * pmean));
    }
    for o in rec.outside.iter().chain(&rec.inside) {
        let name = format!("{}_offset", o.name);
        vars.push(Var::offset(&name, o.off0, 100.0, outputs.len(), Vec::new()));
        outputs.push(Output::new(&o.name, at(o.state), &o.raw, 1e-6 * pmean));
    }
    outputs
}

/// The gas at the window start: the measured pressures (offsets removed), the masses sharing
/// the model's inventory in proportion to `P V / T_rest` at the measured angle.
fn initial_gas(
    model: &dyn Model,
    layout: &StateLayout,
    rec: &Record,
    p: &[f64],
    eq: &[f64],
    x: &mut [f64],
) {
    let ta = rec.tr.0;
    let sp = rec.sig_p.as_ref().expect("checked");
    let hot = rec
        .sig_ph
        .as_ref()
        .filter(|_| rec.have_hot)
        .map(|s| s.val[ta] - rec.ph_off0)
        .unwrap_or(0.0);
    let ps = &layout.pressures;
    for (i, &s) in ps.iter().enumerate() {
        let wc = cold_weight(i, ps.len(), rec.have_hot);
        x[s] = wc * (sp.val[ta] - rec.p_off0) + (1.0 - wc) * hot;
    }
    for o in rec.outside.iter().chain(&rec.inside) {
        x[o.state] = o.sig.val[ta] - o.off0;
    }
    crate::fit::measured_state::mass_states(model, p, layout, eq, x);
    // the rest state's inventory scaled to the measured pressures (at the rest temperatures):
    // a leak lets the running engine's inventory differ from the rest state's
    let scale = pv_over_t(model, p, layout, eq, x) / pv_over_t(model, p, layout, eq, eq);
    if scale.is_finite() && scale > 0.0 {
        for &m in &layout.masses {
            x[m] *= scale;
        }
    }
}

/// `sum P V / T_rest` over the working gas's CVs at the state `x` (the rest temperatures
/// from `eq`).
fn pv_over_t(model: &dyn Model, p: &[f64], layout: &StateLayout, eq: &[f64], x: &[f64]) -> f64 {
    let nv = model.vessel_names().len();
    let (mut pr, mut vol, mut t) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    model.pv(p, x, &mut pr, &mut vol);
    model.temperatures(p, eq, &mut t);
    let states = model.states();
    layout
        .pressures
        .iter()
        .filter_map(|&s| match states[s].kind {
            StateKind::Pressure(k) => Some(x[s] * vol[k] / t[k]),
            _ => None,
        })
        .sum()
}
