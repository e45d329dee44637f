//! Schmidt's isothermal analysis of a kinematic engine, on the model's own volumes.
//!
//! Schmidt (1871) takes every space of the working gas at a fixed temperature `T_i` and the
//! pressure uniform: with the gas mass `m`, `p(theta) = m R / sum_i V_i(theta) / T_i`, where
//! `V_i(theta)` are the spaces' volumes at the crank angle (here the model's own volume
//! expressions through its cranks, so any mechanism a file declares is analysed as written,
//! not a sinusoidal idealisation). The indicated work per revolution is
//! `W = closed-integral p dV = integral p dV/dtheta dtheta` over one turn, by the trapezoid
//! rule on a uniform grid of the angle (spectrally accurate for the smooth periodic
//! integrand); each space's share `W_i = integral p dV_i/dtheta dtheta` is its heat, and
//! `sum_i W_i / T_i = 0` (the gas's entropy returns), so with two temperatures `W = W_hot
//! (1 - T_cold / T_hot)`: Carnot's efficiency, the upper bound every real cycle falls short of.
//!
//! Which temperatures: the caller's. `stirling simulate` takes each space's cycle-mean gas
//! temperature from the run (the isothermal limit of this engine as it runs), so the ratio of
//! the model's indicated work to Schmidt's measures what the finite heat transfer, the flow
//! losses and the leak cost, not how far the gas's temperatures fall short of the plates'.

use std::f64::consts::TAU;

use stirling_dsl::{Model, StateKind};

use super::indicated::{angle_state, IndicatedError};
use crate::layout::StateLayout;

/// Angle samples of one revolution.
const GRID: usize = 720;
/// Angle step of the volume slopes' fourth-order central differences (rad): truncation about
/// `H^4 / 30` and cancellation about `1e-16 / H` of the slope's scale, both near 1e-13.
const H: f64 = 1e-3;

/// Why Schmidt's analysis could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SchmidtError {
    #[error(transparent)]
    Indicated(#[from] IndicatedError),
    #[error("model `{model}` has no parameter `R` (the specific gas constant) for Schmidt's p = m R / sum V/T")]
    NoGasConstant { model: String },
    #[error("{got} temperatures for the {spaces} spaces of the working gas ({names})")]
    Temperatures {
        got: usize,
        spaces: usize,
        names: String,
    },
    #[error("the temperature of `{space}` is {value} K: Schmidt's spaces need a finite temperature above 0 K")]
    Temperature { space: String, value: f64 },
    #[error("the gas mass is {0} kg: Schmidt's analysis needs a finite mass above 0")]
    Mass(f64),
}

/// One space of the analysis.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SchmidtSpace {
    pub name: String,
    /// Its temperature (K).
    pub temperature: f64,
    /// Its share of the work per revolution, `integral p dV_i` (J): the heat it takes in.
    pub work: f64,
}

/// Schmidt's figures of one revolution.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Schmidt {
    /// The gas mass (kg).
    pub mass: f64,
    pub spaces: Vec<SchmidtSpace>,
    /// Indicated work per revolution (J).
    pub work: f64,
    /// The pressure's least, greatest and mean over the revolution (Pa).
    pub p_min: f64,
    pub p_max: f64,
    pub p_mean: f64,
}

/// The spaces of the working gas: `(name, vessel index)` in the order of
/// [`StateLayout::working_gas`].
pub fn working_spaces(model: &dyn Model) -> Vec<(String, usize)> {
    let states = model.states();
    let names = model.vessel_names();
    StateLayout::working_gas(model)
        .pressures
        .iter()
        .filter_map(|&s| match states[s].kind {
            StateKind::Pressure(k) => Some((names.get(k).cloned().unwrap_or_default(), k)),
            _ => None,
        })
        .collect()
}

/// Schmidt's analysis of the kinematic `model` at parameters `p`: the spaces of the working
/// gas ([`working_spaces`]) at `temperatures` (K, one each, in that order), holding the gas
/// mass `mass` (kg).
pub fn schmidt(
    model: &dyn Model,
    p: &[f64],
    temperatures: &[f64],
    mass: f64,
) -> Result<Schmidt, SchmidtError> {
    let ia = angle_state(model)?;
    let spaces = working_spaces(model);
    check(model, &spaces, temperatures, mass)?;
    let r = model
        .param_index("R")
        .map(|i| p[i])
        .ok_or_else(|| SchmidtError::NoGasConstant {
            model: model.name().into(),
        })?;
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let nv = model.vessel_names().len();
    let mut volumes = |angle: f64| -> Vec<f64> {
        x[ia] = angle;
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(p, &x, &mut pr, &mut vol);
        spaces.iter().map(|(_, k)| vol[*k]).collect()
    };
    let dtheta = TAU / GRID as f64;
    let mut works = vec![0.0; spaces.len()];
    let mut pressures = Vec::with_capacity(GRID);
    for g in 0..GRID {
        let a = g as f64 * dtheta;
        let v = volumes(a);
        let pressure = mass * r / v.iter().zip(temperatures).map(|(v, t)| v / t).sum::<f64>();
        let (u2, u1, d1, d2) = (
            volumes(a + 2.0 * H),
            volumes(a + H),
            volumes(a - H),
            volumes(a - 2.0 * H),
        );
        for (k, w) in works.iter_mut().enumerate() {
            let slope = (8.0 * (u1[k] - d1[k]) - (u2[k] - d2[k])) / (12.0 * H);
            *w += pressure * slope * dtheta;
        }
        pressures.push(pressure);
    }
    let fold = |f: fn(f64, f64) -> f64, init: f64| pressures.iter().copied().fold(init, f);
    Ok(Schmidt {
        mass,
        work: works.iter().sum(),
        spaces: spaces
            .iter()
            .zip(temperatures)
            .zip(&works)
            .map(|(((name, _), &temperature), &work)| SchmidtSpace {
                name: name.clone(),
                temperature,
                work,
            })
            .collect(),
        p_min: fold(f64::min, f64::INFINITY),
        p_max: fold(f64::max, f64::NEG_INFINITY),
        p_mean: pressures.iter().sum::<f64>() / GRID as f64,
    })
}

/// The temperatures and the mass, checked against the spaces.
fn check(
    model: &dyn Model,
    spaces: &[(String, usize)],
    temperatures: &[f64],
    mass: f64,
) -> Result<(), SchmidtError> {
    if temperatures.len() != spaces.len() {
        let names: Vec<&str> = spaces.iter().map(|(n, _)| n.as_str()).collect();
        return Err(SchmidtError::Temperatures {
            got: temperatures.len(),
            spaces: spaces.len(),
            names: format!("{}: {}", model.name(), names.join(", ")),
        });
    }
    for ((name, _), &t) in spaces.iter().zip(temperatures) {
        if !(t.is_finite() && t > 0.0) {
            return Err(SchmidtError::Temperature {
                space: name.clone(),
                value: t,
            });
        }
    }
    if !(mass.is_finite() && mass > 0.0) {
        return Err(SchmidtError::Mass(mass));
    }
    Ok(())
}
