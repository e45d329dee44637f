//! Breaking the feedback loop at a pressure-force input (docs/physics.md section 7).
//!
//! The linearized engine `x' = J x` is read as a plant driven by a scalar input `u` that is fed
//! back from the states: `x' = A0 x + B u`, `u = -K x`, with `A0 - B K = J`. The open loop is
//! `L(s) = K (sI - A0)^-1 B` (negative feedback, as MATLAB's `margin`).
//!
//! - Channel [`Channel::Body`](crate::linear::loop_break::Channel::Body)`(k)`: `u` is the pressure
//!   force on body `k`. `B = e_v / m_k` (`e_v` the unit vector of the body's velocity, `m_k` its
//!   declared mass), `C = grad F_k`, `K = -C`, `A0 = J - B C`; the other bodies' forces stay
//!   closed.
//! - Channel [`Channel::Pressure`](crate::linear::loop_break::Channel::Pressure) (single-pressure
//!   models such as `schmidt` and `cv1`): `u` is the common pressure `P - P_eq` acting on every
//!   face. Then `grad F_k = a_k grad P` for all bodies, `B = sum_k a_k e_vk / m_k`, `C = grad P`,
//!   `K = -C`. The face sums `a_k` and `grad P` are recovered from the force gradients up to one
//!   scalar, fixed by the slope of the varying vessel pressure of [`Model::pv`] along `grad F` (a
//!   central difference; the scale does not change `L`, only the units of `B` and `C`). For
//!   `schmidt` this gives `B = [0, -Ar/md, 0, -(A-Ar)/mp]'` and `u = P - Pmean`.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use stirling_dsl::{Model, StateKind};

use super::equilibrium::state_scales;
use super::LinearError;

/// Where the loop is broken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Channel {
    /// The common pressure of a single-pressure model.
    Pressure,
    /// The pressure force on body `k`.
    Body(usize),
}

/// The open loop as a state-space triple in the model's full state coordinates.
#[derive(Clone, Debug)]
pub struct LoopBreak {
    pub channel: Channel,
    /// `pressure` or the body's name.
    pub name: String,
    /// Unit of `u` (`Pa` or `N`).
    pub unit: &'static str,
    /// `A0 = J - B C` (empty `0 x 0` on the sparse route).
    pub a: DMatrix<f64>,
    /// Input column.
    pub b: DVector<f64>,
    /// Output row `C` (`u = C x` is the signal that closes the loop as `u = -K x`, `K = -C`).
    pub c: DVector<f64>,
}

impl LoopBreak {
    /// The feedback gain `K = -C`.
    pub fn k(&self) -> DVector<f64> {
        -&self.c
    }
}

/// The names of the channels a model offers: `pressure` (single-pressure models) and its bodies.
pub fn channel_names(model: &dyn Model, p: &[f64], x: &[f64]) -> Vec<String> {
    let mut v = Vec::new();
    if pressure_split(model, p, x).is_ok() {
        v.push("pressure".to_string());
    }
    v.extend(model.bodies().iter().map(|b| b.name.to_string()));
    v
}

/// Parse a channel name (`pressure` or a body name).
pub fn parse_channel(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    name: &str,
) -> Result<Channel, LinearError> {
    let unknown = || LinearError::UnknownChannel {
        name: name.to_string(),
        model: model.name().to_string(),
        valid: channel_names(model, p, x).join(", "),
    };
    if name == "pressure" {
        return pressure_split(model, p, x)
            .map(|_| Channel::Pressure)
            .map_err(|_| unknown());
    }
    model
        .bodies()
        .iter()
        .position(|b| b.name == name)
        .map(Channel::Body)
        .ok_or_else(unknown)
}

/// The default: the common pressure where there is one (it reproduces the seed's Figure 8 for
/// `schmidt`), else the body named `piston`, else the last body.
pub fn default_channel(model: &dyn Model, p: &[f64], x: &[f64]) -> Channel {
    if pressure_split(model, p, x).is_ok() {
        return Channel::Pressure;
    }
    let bodies = model.bodies();
    Channel::Body(
        bodies
            .iter()
            .position(|b| b.name == "piston")
            .unwrap_or(bodies.len().saturating_sub(1)),
    )
}

fn velocity_index(model: &dyn Model, k: usize) -> usize {
    model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Velocity(k))
        .expect("every body has a velocity state")
}

fn gradient(model: &dyn Model, k: usize, p: &[f64], x: &[f64]) -> DVector<f64> {
    let mut g = vec![0.0; x.len()];
    model.pressure_force_gradient(k, p, x, &mut g);
    DVector::from_vec(g)
}

/// Break the loop of `j` (the Jacobian at `x`) at `channel`.
pub fn break_loop(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    j: &DMatrix<f64>,
    channel: Channel,
) -> Result<LoopBreak, LinearError> {
    let mut lb = break_loop_input(model, p, x, channel)?;
    let mut a = j.clone();
    a.ger(-1.0, &lb.b, &lb.c, 1.0);
    lb.a = a;
    Ok(lb)
}

/// [`break_loop`] without `A0` (left `0 x 0`): `B` and `C` only, for large models whose
/// `A0 = J - B C` is used in sparse form.
pub fn break_loop_input(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
    channel: Channel,
) -> Result<LoopBreak, LinearError> {
    let n = x.len();
    let mut masses = vec![0.0; model.bodies().len()];
    model.body_masses(p, &mut masses);
    let (b, c, name, unit) = match channel {
        Channel::Body(k) => {
            let body = model
                .bodies()
                .get(k)
                .ok_or_else(|| LinearError::UnknownChannel {
                    name: format!("body #{k}"),
                    model: model.name().to_string(),
                    valid: channel_names(model, p, x).join(", "),
                })?;
            let mut b = DVector::zeros(n);
            b[velocity_index(model, k)] = 1.0 / masses[k];
            (b, gradient(model, k, p, x), body.name.to_string(), "N")
        }
        Channel::Pressure => {
            let (a, grad_p) = pressure_split(model, p, x)?;
            let mut b = DVector::zeros(n);
            for (k, ak) in a.iter().enumerate() {
                b[velocity_index(model, k)] += ak / masses[k];
            }
            (b, grad_p, "pressure".to_string(), "Pa")
        }
    };
    Ok(LoopBreak {
        channel,
        name,
        unit,
        a: DMatrix::zeros(0, 0),
        b,
        c,
    })
}

/// For a single-pressure model: the face sums `a_k` (`F_k = a_k P + const`) and `grad P`.
fn pressure_split(
    model: &dyn Model,
    p: &[f64],
    x: &[f64],
) -> Result<(Vec<f64>, DVector<f64>), LinearError> {
    let not_single = || LinearError::NotSinglePressure {
        model: model.name().to_string(),
    };
    let grads: Vec<DVector<f64>> = (0..model.bodies().len())
        .map(|k| gradient(model, k, p, x))
        .collect();
    let r = (0..grads.len())
        .max_by(|&a, &b| grads[a].norm().total_cmp(&grads[b].norm()))
        .ok_or_else(not_single)?;
    let gr = &grads[r];
    let gg = gr.norm_squared();
    if gg == 0.0 {
        return Err(not_single());
    }
    let mut ratio = Vec::with_capacity(grads.len());
    for g in &grads {
        let t = g.dot(gr) / gg;
        if (g - gr * t).norm() > 1e-9 * g.norm().max(gr.norm()) {
            return Err(not_single());
        }
        ratio.push(t);
    }
    // a_r from the slope of the varying pressure along d = gr / |gr|: dP/dh = grad P . d = |gr| / a_r.
    let slope = pressure_slope(model, p, x, gr).ok_or_else(not_single)?;
    let a_r = gr.norm() / slope;
    Ok((ratio.iter().map(|t| t * a_r).collect(), gr / a_r))
}

/// `dP/dh` of the most varying vessel pressure along `g / |g|` (central difference).
fn pressure_slope(model: &dyn Model, p: &[f64], x: &[f64], g: &DVector<f64>) -> Option<f64> {
    let d = g / g.norm();
    let s = state_scales(model, x);
    let h = d
        .iter()
        .zip(&s)
        .filter(|(di, _)| **di != 0.0)
        .map(|(di, si)| 1e-6 * si / di.abs())
        .fold(f64::INFINITY, f64::min);
    let nv = model.vessel_names().len();
    let at = |sign: f64| {
        let xs: Vec<f64> = x
            .iter()
            .zip(d.iter())
            .map(|(a, b)| a + sign * h * b)
            .collect();
        let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(p, &xs, &mut pr, &mut vol);
        pr
    };
    let (plus, minus) = (at(1.0), at(-1.0));
    let slopes = plus.iter().zip(&minus).map(|(a, b)| (a - b) / (2.0 * h));
    let best = slopes.max_by(|a, b| a.abs().total_cmp(&b.abs()))?;
    (best != 0.0 && best.is_finite()).then_some(best)
}
