//! A kinematic engine as it runs: its speed, the indicated work of its last whole revolutions,
//! and the cycle-mean state of its gas (what Schmidt's analysis is then made at,
//! [`crate::sim::schmidt`]).
//!
//! A flywheel's angle grows by `2 pi` a revolution, so no state returns and there is no
//! periodic orbit to shoot (`--limit-cycle` refuses such a model); the engine is pushed
//! (`--start omega=...`) and run until it turns steadily, and the figures are taken over the
//! last whole revolutions of the run's second half (the first half is the start-up).

use std::f64::consts::TAU;

use stirling_dsl::Model;

use super::indicated::{angle_state, work_per_revolution, IndicatedError};
use super::schmidt::working_spaces;
use crate::layout::StateLayout;

/// Revolutions averaged at most.
const REVS: usize = 10;
/// Angle step of the volume slopes' central differences (rad).
const H: f64 = 1e-6;

/// The running engine's figures over its last whole revolutions.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Running {
    pub revolutions: usize,
    /// Mean speed (revolutions per second).
    pub hz: f64,
    /// `(max - min) / mean` of the angular velocity over the revolutions.
    pub ripple: f64,
    /// Indicated work per revolution, `sum_i closed-integral P_i dV_i` (J), and each space's.
    pub work: f64,
    pub work_per_space: Vec<(String, f64)>,
    /// Indicated power, work times speed (W).
    pub power: f64,
    /// Cycle-mean gas temperature of each space of the working gas (K).
    pub temperatures: Vec<(String, f64)>,
    /// Cycle-mean mass of the working gas (kg).
    pub mass: f64,
}

/// The running figures of a run (`t`, states `x` per sample) of the kinematic `model`.
pub fn running(
    model: &dyn Model,
    p: &[f64],
    t: &[f64],
    x: &[Vec<f64>],
) -> Result<Running, IndicatedError> {
    let ia = angle_state(model)?;
    let iw = StateLayout::flywheels(model).first().map_or(ia, |w| w.1);
    let half = t
        .iter()
        .position(|&s| s >= t.last().copied().unwrap_or(0.0) / 2.0);
    let theta: Vec<f64> = x.iter().map(|s| s[ia]).collect();
    let (Some(h), Some(&last)) = (half, theta.last()) else {
        return Err(no_revolution(&theta));
    };
    let turns = ((last - theta[h]) / TAU).floor();
    if !(turns >= 2.0) {
        return Err(IndicatedError::NoRevolution {
            turned: last - theta[h],
            from: theta[h],
            to: last,
        });
    }
    let revs = (turns as usize - 1).min(REVS);
    let from = last - (revs as f64 + 1.0) * TAU;
    let k0 = theta.iter().position(|&a| a >= from).unwrap_or(h).max(h);
    let win = &x[k0..];
    let th = &theta[k0..];
    let spaces = working_spaces(model);
    let nv = model.vessel_names().len();
    let pv = |s: &[f64]| {
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(p, s, &mut pr, &mut vol);
        (pr, vol)
    };
    // every vessel's pressure and `dV/dtheta` at each sample, one evaluation each
    let pressure: Vec<Vec<f64>> = win.iter().map(|s| pv(s).0).collect();
    let slope: Vec<Vec<f64>> = win.iter().map(|s| volume_slopes(&pv, s, ia)).collect();
    let mut work_per_space = Vec::new();
    let mut turned = revs;
    for (name, k) in &spaces {
        let pk: Vec<f64> = pressure.iter().map(|v| v[*k]).collect();
        let sk: Vec<f64> = slope.iter().map(|v| v[*k]).collect();
        let (w, n) = work_per_revolution(th, &sk, &pk)?;
        work_per_space.push((name.clone(), w));
        turned = n;
    }
    let (t0, t1) = (t[k0], t[t.len() - 1]);
    let hz = (th[th.len() - 1] - th[0]) / (t1 - t0) / TAU;
    let omega: Vec<f64> = win.iter().map(|s| s[iw]).collect();
    let (lo, hi) = omega
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
            (a.min(w), b.max(w))
        });
    let work: f64 = work_per_space.iter().map(|w| w.1).sum();
    let (temperatures, mass) = gas_means(model, p, win, &spaces);
    Ok(Running {
        revolutions: turned,
        hz,
        ripple: (hi - lo) / (hz * TAU),
        work,
        work_per_space,
        power: work * hz,
        temperatures,
        mass,
    })
}

/// `dV/dtheta` of every vessel at the state `s` (the cranks follow the angle `ia`).
fn volume_slopes(pv: &impl Fn(&[f64]) -> (Vec<f64>, Vec<f64>), s: &[f64], ia: usize) -> Vec<f64> {
    let (mut up, mut dn) = (s.to_vec(), s.to_vec());
    up[ia] += H;
    dn[ia] -= H;
    let (vu, vd) = (pv(&up).1, pv(&dn).1);
    vu.iter()
        .zip(&vd)
        .map(|(a, b)| (a - b) / (2.0 * H))
        .collect()
}

/// The mean gas temperature of each space over the samples `win`, and the mean mass of the
/// working gas (`P V / (R T)` summed over the spaces; `R` the model's parameter, else air's).
fn gas_means(
    model: &dyn Model,
    p: &[f64],
    win: &[Vec<f64>],
    spaces: &[(String, usize)],
) -> (Vec<(String, f64)>, f64) {
    let r = model.param_index("R").map_or(287.05, |i| p[i]);
    let nv = model.vessel_names().len();
    let mut temp = vec![0.0; spaces.len()];
    let mut mass = 0.0;
    for s in win {
        let mut tv = vec![0.0; nv];
        model.temperatures(p, s, &mut tv);
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(p, s, &mut pr, &mut vol);
        for (j, (_, k)) in spaces.iter().enumerate() {
            temp[j] += tv[*k];
            mass += pr[*k] * vol[*k] / (r * tv[*k]);
        }
    }
    let n = win.len().max(1) as f64;
    (
        spaces
            .iter()
            .zip(temp)
            .map(|((name, _), t)| (name.clone(), t / n))
            .collect(),
        mass / n,
    )
}

fn no_revolution(theta: &[f64]) -> IndicatedError {
    let (from, to) = (
        theta.first().copied().unwrap_or(0.0),
        theta.last().copied().unwrap_or(0.0),
    );
    IndicatedError::NoRevolution {
        turned: to - from,
        from,
        to,
    }
}
