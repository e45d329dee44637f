//! Periodic motion: successive upward zero crossings of a position define cycles;
//! the motion is periodic when the last periods and the crossing states agree.
//! Cycle figures come from uniform samples over one period: amplitudes
//! `(max - min)/2`, and the displacer-piston phase angle
//! `arg(X1) - arg(Y1)` of the first Fourier harmonics (positive: displacer leads).

use std::f64::consts::PI;

use stirling_dsl::{Model, StateKind};

use super::integrate::Crossing;

/// Whether the last `cycles` periods (and the crossing states, relative to
/// `scale`) agree within `tol`; returns the last period if so.
pub fn periodic(crossings: &[Crossing], scale: &[f64], cycles: usize, tol: f64) -> Option<f64> {
    if crossings.len() < cycles + 2 {
        return None;
    }
    let last = &crossings[crossings.len() - cycles - 2..];
    let periods: Vec<f64> = last.windows(2).map(|w| w[1].t - w[0].t).collect();
    let tp = *periods.last()?;
    let same_period = periods.iter().all(|q| (q - tp).abs() <= tol * tp);
    let end = &last[last.len() - 1].x;
    let same_state = last.iter().all(|c| {
        c.x.iter()
            .zip(end)
            .zip(scale)
            .all(|((a, b), s)| (a - b).abs() <= tol * s)
    });
    (same_period && same_state).then_some(tp)
}

/// Amplitudes and phase over one period.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleFigures {
    pub period: f64,
    pub frequency_hz: f64,
    /// Displacer amplitude (m).
    pub x_amp: f64,
    /// Piston amplitude (m).
    pub y_amp: f64,
    /// Amplitude of every pressure state (Pa), or of the one algebraic pressure.
    pub p_amp: Vec<f64>,
    /// Phase of the displacer ahead of the piston (deg, in (-180, 180]).
    pub phase_deg: f64,
}

/// Figures from `states` sampled uniformly over one period (first sample at
/// `t0`, last at `t0 + period`, inclusive).
pub fn figures(model: &dyn Model, p: &[f64], period: f64, states: &[Vec<f64>]) -> CycleFigures {
    let kinds = model.states();
    let col = |k: usize| -> Vec<f64> { states.iter().map(|x| x[k]).collect() };
    let pos = |b: usize| kinds.iter().position(|s| s.kind == StateKind::Position(b));
    let xs = pos(0).map(col).unwrap_or_default();
    let ys = pos(1).map(col).unwrap_or_default();
    let pressures: Vec<Vec<f64>> = {
        let pk = crate::layout::StateLayout::of(model).pressures;
        if pk.is_empty() {
            // algebraic pressure (schmidt): the first vessel of `pv`
            let nv = model.vessel_names().len();
            vec![states
                .iter()
                .map(|x| {
                    let (mut pr, mut v) = (vec![0.0; nv], vec![0.0; nv]);
                    model.pv(p, x, &mut pr, &mut v);
                    pr[0]
                })
                .collect()]
        } else {
            pk.into_iter().map(col).collect()
        }
    };
    let amp = |s: &[f64]| {
        (s.iter().cloned().fold(f64::MIN, f64::max) - s.iter().cloned().fold(f64::MAX, f64::min))
            / 2.0
    };
    let phase = (harmonic_phase(&xs) - harmonic_phase(&ys)).to_degrees();
    CycleFigures {
        period,
        frequency_hz: 1.0 / period,
        x_amp: amp(&xs),
        y_amp: amp(&ys),
        p_amp: pressures.iter().map(|s| amp(s)).collect(),
        phase_deg: wrap_deg(phase),
    }
}

/// Phase of the first harmonic of a periodic sample (last sample = first, dropped).
fn harmonic_phase(s: &[f64]) -> f64 {
    let n = s.len().saturating_sub(1).max(1);
    let (mut re, mut im) = (0.0, 0.0);
    for (k, v) in s.iter().take(n).enumerate() {
        let a = 2.0 * PI * k as f64 / n as f64;
        re += v * a.cos();
        im += v * a.sin();
    }
    // x(t) = |X| cos(w t + phi)  =>  sum x e^{-i w t} ~ |X| e^{i phi}
    (-im).atan2(re)
}

fn wrap_deg(a: f64) -> f64 {
    let mut a = a % 360.0;
    if a <= -180.0 {
        a += 360.0;
    }
    if a > 180.0 {
        a -= 360.0;
    }
    a
}

/// Result of running until the motion repeats.
#[derive(Clone, Debug, PartialEq)]
pub struct Settled {
    /// State at the last upward crossing of `y = 0`.
    pub x0: Vec<f64>,
    /// Time of that crossing and the last period.
    pub t: f64,
    pub period: f64,
    /// The whole sampled run (for the start-up plot).
    pub trajectory: super::integrate::Trajectory,
}

/// Run from `x0` until `cycles` successive periods agree within `tol` (relative,
/// states relative to their magnitudes) or `t_max` is reached.
pub fn settle(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    t_max: f64,
    samples: &[f64],
    cycles: usize,
    tol: f64,
    opts: &super::integrate::SimOptions,
    mut progress: Option<&mut dyn FnMut(f64)>,
) -> Result<Settled, super::SimError> {
    use super::integrate::{integrate, Hooks};
    use super::system::{state_scale, ModelSystem};
    let iy = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(1))
        .ok_or_else(|| {
            super::SimError::BadOption("cycle detection needs the power piston position".into())
        })?;
    let scale = state_scale(model, p);
    let mut found = None;
    let mut on_crossing = |c: &[Crossing]| {
        found = periodic(c, &scale, cycles, tol);
        found.is_some()
    };
    let checker = super::physical::PhysicalCheck::new(model, p);
    let check = |t: f64, x: &[f64]| checker.check(t, x);
    let mut prog = |t: f64| {
        if let Some(f) = progress.as_mut() {
            f(t)
        }
    };
    let hooks = Hooks {
        crossing: Some(iy),
        on_crossing: Some(&mut on_crossing),
        check: Some(&check),
        progress: Some(&mut prog),
        on_step: None,
    };
    let tr = integrate(&ModelSystem { model, p }, x0, t_max, samples, opts, hooks)?;
    let last = tr.crossings.last().cloned();
    match (found, last) {
        (Some(period), Some(c)) => Ok(Settled {
            x0: c.x,
            t: c.t,
            period,
            trajectory: tr,
        }),
        _ => Err(super::SimError::NotPeriodic {
            t: tr.t_end,
            crossings: tr.crossings.len(),
        }),
    }
}
