//! The indicated work of a sampled p-V record: the working gas's volume of a kinematic engine
//! at a crank angle (the model's own volume expressions, through [`Model::pv`]), and the loop
//! integral `closed-integral p dV` over whole revolutions of a measured angle.
//!
//! The work is positive when the loop runs clockwise in the (V, p) plane (work done by the
//! gas). `loop_work` is the area of the polygon through the samples, which cuts the loop's
//! corners: an ellipse sampled at `N` points loses `1 - sin(2 pi / N) / (2 pi / N)` of its
//! area (0.4 % at 39 samples a revolution, the gamma LTD at 100 Hz). `work_per_revolution`
//! integrates `p dV/dtheta` over the angle instead, with the volume's slope from the model's
//! expressions (`volume_slope_at_angles`): the trapezoid rule on a smooth periodic integrand,
//! exact to round-off for a sampled ellipse. Noise in `p` biases neither.

use std::f64::consts::TAU;

use stirling_dsl::{Model, StateKind};

use crate::layout::StateLayout;

/// Why a volume or a loop's work could not be had.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IndicatedError {
    #[error("model `{model}` has no flywheel: its volume is not a function of a crank angle")]
    NoFlywheel { model: String },
    #[error("model `{model}` has {wheels} flywheels: the volume of one angle is ambiguous")]
    Flywheels { model: String, wheels: usize },
    #[error("{what}: {a} values against {b}: a loop needs as many volumes as pressures")]
    Lengths {
        what: &'static str,
        a: usize,
        b: usize,
    },
    #[error("{what}: sample {index} is not finite ({value})")]
    NotFinite {
        what: &'static str,
        index: usize,
        value: f64,
    },
    #[error(
        "the angle turns by {turned:.3} rad (from {from:.3} to {to:.3}): a loop needs at \
         least one whole revolution (2 pi rad) in increasing angle"
    )]
    NoRevolution { turned: f64, from: f64, to: f64 },
}

/// The flywheel's angle state of `model` (its only flywheel).
pub fn angle_state(model: &dyn Model) -> Result<usize, IndicatedError> {
    let wheels = StateLayout::flywheels(model);
    match wheels.as_slice() {
        [(angle, _)] => Ok(*angle),
        [] => Err(IndicatedError::NoFlywheel {
            model: model.name().into(),
        }),
        w => Err(IndicatedError::Flywheels {
            model: model.name().into(),
            wheels: w.len(),
        }),
    }
}

/// The working gas's volume (m^3) at the state `x`: the sum of the volumes of the CVs whose
/// pressure is a state of the working gas (the spaces and CVs outside it are left out).
pub fn working_volume(model: &dyn Model, p: &[f64], x: &[f64]) -> f64 {
    let nv = model.vessel_names().len();
    let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
    model.pv(p, x, &mut pr, &mut vol);
    let states = model.states();
    StateLayout::working_gas(model)
        .pressures
        .iter()
        .filter_map(|&s| match states[s].kind {
            StateKind::Pressure(k) => vol.get(k).copied(),
            _ => None,
        })
        .sum()
}

/// The working gas's volume (m^3) of the kinematic `model` at each crank angle of `theta`
/// (rad): the rest state with the flywheel's angle set (the cranks follow it).
pub fn volume_at_angles(
    model: &dyn Model,
    p: &[f64],
    theta: &[f64],
) -> Result<Vec<f64>, IndicatedError> {
    let ia = angle_state(model)?;
    finite("the angle", theta)?;
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    Ok(theta
        .iter()
        .map(|&a| {
            x[ia] = a;
            working_volume(model, p, &x)
        })
        .collect())
}

/// `dV/dtheta` (m^3/rad) of the working gas of the kinematic `model` at each crank angle of
/// `theta` (rad): central differences of [`volume_at_angles`] over 1e-6 rad (the volume is a
/// smooth function of the angle; the difference's error is below 1e-9 of the slope's scale).
pub fn volume_slope_at_angles(
    model: &dyn Model,
    p: &[f64],
    theta: &[f64],
) -> Result<Vec<f64>, IndicatedError> {
    let h = 1e-6;
    let up: Vec<f64> = theta.iter().map(|a| a + h).collect();
    let dn: Vec<f64> = theta.iter().map(|a| a - h).collect();
    let (vu, vd) = (
        volume_at_angles(model, p, &up)?,
        volume_at_angles(model, p, &dn)?,
    );
    Ok(vu
        .iter()
        .zip(&vd)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect())
}

/// `closed-integral p dV` of the closed polygon through `(v[i], p[i])` (the last point joined
/// to the first), by the trapezoid rule: exact for a polygon, spectrally accurate for a smooth
/// periodic loop sampled uniformly.
pub fn loop_work(v: &[f64], p: &[f64]) -> Result<f64, IndicatedError> {
    same_length("the loop", v, p)?;
    finite("the loop's volume", v)?;
    finite("the loop's pressure", p)?;
    let n = v.len();
    Ok((0..n)
        .map(|i| {
            let j = (i + 1) % n;
            0.5 * (p[i] + p[j]) * (v[j] - v[i])
        })
        .sum())
}

/// The whole revolutions of the increasing angle `theta` (rad) from its first sample: their
/// number, and the index of the first sample at or past their end (the samples before it lie
/// within them).
pub fn whole_revolutions(theta: &[f64]) -> Result<(usize, usize), IndicatedError> {
    finite("the angle", theta)?;
    let (from, to) = match (theta.first(), theta.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => {
            return Err(IndicatedError::NoRevolution {
                turned: 0.0,
                from: 0.0,
                to: 0.0,
            })
        }
    };
    let turns = ((to - from) / TAU).floor();
    if !(turns >= 1.0) {
        return Err(IndicatedError::NoRevolution {
            turned: to - from,
            from,
            to,
        });
    }
    let end = from + turns * TAU;
    // the first sample past the end angle (the angle increases, up to its noise)
    let j = theta
        .iter()
        .position(|&a| a >= end)
        .unwrap_or(theta.len() - 1)
        .max(1);
    Ok((turns as usize, j))
}

/// The work per revolution `integral p dV/dtheta dtheta / turns` over the whole revolutions of
/// the increasing angle `theta` (rad) from its first sample ([`whole_revolutions`]), by the
/// trapezoid rule in the angle; the integrand at the end angle (exactly a whole number of
/// turns) is interpolated between its neighbours. `dv` is `dV/dtheta` at each sample
/// (`volume_slope_at_angles`). Returns the work and the number of revolutions.
pub fn work_per_revolution(
    theta: &[f64],
    dv: &[f64],
    p: &[f64],
) -> Result<(f64, usize), IndicatedError> {
    same_length("the angle and the volume's slope", theta, dv)?;
    same_length("the volume's slope and the pressure", dv, p)?;
    finite("the volume's slope", dv)?;
    finite("the pressure", p)?;
    let (turns, j) = whole_revolutions(theta)?;
    let end = theta[0] + turns as f64 * TAU;
    let f: Vec<f64> = p.iter().zip(dv).map(|(p, d)| p * d).collect();
    let seg = |a: f64, b: f64, fa: f64, fb: f64| 0.5 * (fa + fb) * (b - a);
    let mut w: f64 = (1..j)
        .map(|i| seg(theta[i - 1], theta[i], f[i - 1], f[i]))
        .sum();
    if theta[j] > theta[j - 1] {
        let s = ((end - theta[j - 1]) / (theta[j] - theta[j - 1])).clamp(0.0, 1.0);
        let fe = f[j - 1] + s * (f[j] - f[j - 1]);
        w += seg(theta[j - 1], end, f[j - 1], fe);
    }
    Ok((w / turns as f64, turns))
}

fn same_length(what: &'static str, a: &[f64], b: &[f64]) -> Result<(), IndicatedError> {
    if a.len() != b.len() {
        return Err(IndicatedError::Lengths {
            what,
            a: a.len(),
            b: b.len(),
        });
    }
    Ok(())
}

fn finite(what: &'static str, v: &[f64]) -> Result<(), IndicatedError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(IndicatedError::NotFinite {
            what,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// An ellipse `V = a cos t`, `p = -b sin t` (clockwise) at `n` uniform samples of `t`.
    fn ellipse(a: f64, b: f64, n: usize, turns: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|i| turns * TAU * i as f64 / n as f64).collect();
        let v = t.iter().map(|s| 1.0 + a * s.cos()).collect();
        let p = t.iter().map(|s| 5.0 - b * s.sin()).collect();
        (t, v, p)
    }

    #[test]
    fn a_sampled_ellipse_is_its_inscribed_polygon_clockwise_positive() {
        let n = 40;
        let (_, v, p) = ellipse(2.0, 3.0, n, 1.0);
        let w = loop_work(&v, &p).unwrap();
        // the polygon's area: n triangles of the ellipse's centre, (a b / 2) sin(2 pi / n)
        let polygon = 0.5 * n as f64 * (TAU / n as f64).sin() * 6.0;
        assert!((w - polygon).abs() < 1e-12 * w, "{w} against {polygon}");
        assert!(w < PI * 6.0);
        let back: (Vec<f64>, Vec<f64>) = (
            v.iter().rev().copied().collect(),
            p.iter().rev().copied().collect(),
        );
        assert!((loop_work(&back.0, &back.1).unwrap() + w).abs() < 1e-12 * w);
    }

    #[test]
    fn a_polygon_is_exact() {
        // the unit square, clockwise in (V, p): area 1
        let v = [0.0, 0.0, 1.0, 1.0];
        let p = [0.0, 1.0, 1.0, 0.0];
        assert!((loop_work(&v, &p).unwrap() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn the_angle_integral_of_an_ellipse_is_pi_a_b_per_whole_revolution() {
        // 3 turns at 37 samples a turn, then some: the whole turns are taken
        let n = 3 * 37 + 15;
        let t: Vec<f64> = (0..n).map(|i| TAU * i as f64 / 37.0).collect();
        let p: Vec<f64> = t.iter().map(|s| 5.0 - 3.0 * s.sin()).collect();
        let dv: Vec<f64> = t.iter().map(|s| -2.0 * s.sin()).collect();
        // the end, 3 turns, at sample 111 up to round-off (its neighbour when just short)
        let (k, j) = whole_revolutions(&t).unwrap();
        assert!(k == 3 && (111..=112).contains(&j), "{k} {j}");
        let (w, k) = work_per_revolution(&t, &dv, &p).unwrap();
        assert_eq!(k, 3);
        assert!((w - PI * 6.0).abs() < 1e-12 * PI * 6.0, "{w}");
        // an end between samples (an angle of 36.3 samples a turn) is interpolated: 1e-4
        let t2: Vec<f64> = (0..n).map(|i| TAU * i as f64 / 36.3).collect();
        let dv2: Vec<f64> = t2.iter().map(|s| -2.0 * s.sin()).collect();
        let p2: Vec<f64> = t2.iter().map(|s| 5.0 - 3.0 * s.sin()).collect();
        let (w2, _) = work_per_revolution(&t2, &dv2, &p2).unwrap();
        assert!((w2 - PI * 6.0).abs() < 1e-4 * PI * 6.0, "{w2}");
    }

    #[test]
    fn bad_input_is_refused_by_name() {
        let e = loop_work(&[1.0, 2.0], &[1.0]).unwrap_err();
        assert!(e.to_string().contains("2 values against 1"), "{e}");
        let e = loop_work(&[1.0, f64::NAN, 2.0], &[1.0, 2.0, 3.0]).unwrap_err();
        assert!(e.to_string().contains("sample 1 is not finite"), "{e}");
        let e = work_per_revolution(&[0.0, 1.0, 2.0], &[0.0; 3], &[0.0; 3]).unwrap_err();
        assert!(e.to_string().contains("whole revolution"), "{e}");
        let e = work_per_revolution(&[], &[], &[]).unwrap_err();
        assert!(matches!(e, IndicatedError::NoRevolution { .. }), "{e}");
    }
}
