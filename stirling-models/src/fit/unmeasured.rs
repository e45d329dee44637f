//! Pressures the mechanics need but the record lacks (the seed's engine measured only the cold-side
//! `p`): the gas stage, driven by the measured positions, computes every CV's pressure; its
//! differences to the cold side, `P_i - P_cold`, join the measured `p` as the prescribed pressures
//! of stage 1 (see [`crate::fit::mechanics`]).
//!
//! Why this route: the regenerator pressure drop is set almost entirely by the flow, which
//! the measured positions fix, so the gas stage predicts it well without any mechanical
//! parameter; stage 1 then sees the force `A (P_hot - P_cold)` on the displacer instead of
//! turning it into damping. The estimate depends on the gas parameters, so stage 1's
//! covariance gets the part carried in from stage 2 (the two-step estimator's correction of
//! Murphy and Topel): `G C_2 G^T` with `G = -(J_1^T J_1)^-1 J_1^T dr_1/du_2`, the columns
//! `dr_1/du_2` by central differences of whole runs.

use nalgebra::{DMatrix, DVector};

use super::driven::Stage;
use super::record::Record;
use super::report::FitStats;
use super::sensitivity::Signal;
use super::vars::{Output, Sensor, VarKind};
use super::FitError;
use crate::layout::StateLayout;

/// Relative step of the stage-2 variables for the carried covariance.
const DU: f64 = 0.01;

/// `P_i - P_cold` of the gas stage at its variables `u`, one signal per CV (the cold one is
/// zero), over the whole record (held at the first value before the training start).
pub fn pressure_differences(
    gas: &Stage,
    u: &[f64],
    layout: &StateLayout,
    rec: &Record,
) -> Result<Vec<Signal>, FitError> {
    let (first, last) = (rec.tr.0, rec.data.t.len() - 1);
    let run = pressure_run(gas, u, layout, first, last, false)?;
    let cold = run.yhat.len() - 1;
    Ok(signals(gas, run.yhat.len(), first, last, |i, k| {
        run.yhat[i][k] - run.yhat[cold][k]
    }))
}

/// The derivative of [`pressure_differences`] with respect to the value of the gas stage's
/// variable `var` (at `u`, from the training start `first` to the record's end).
pub fn difference_sensitivity(
    gas: &Stage,
    u: &[f64],
    var: usize,
    first: usize,
) -> Result<Vec<Signal>, FitError> {
    let layout = StateLayout::working_gas(gas.model);
    let last = gas.outputs[0].data.len() - 1;
    let run = pressure_run(gas, u, &layout, first, last, true)?;
    let cold = run.yhat.len() - 1;
    let scale = gas.vars[var].scale;
    Ok(signals(gas, run.yhat.len(), first, last, |i, k| {
        (run.dyhat[i][k][var] - run.dyhat[cold][k][var]) / scale
    }))
}

/// `P_i - P_cold` of the gas stage at its variables `u` for every CV but the cold one, and
/// their derivatives with respect to the value of each variable in `vars`, over samples
/// `0..=last` (held at the first value before `first`): one run, with sensitivities only when
/// `vars` is not empty.
pub fn differences_at(
    gas: &Stage,
    u: &[f64],
    vars: &[usize],
    first: usize,
    last: usize,
) -> Result<(Vec<Signal>, Vec<Vec<Signal>>), FitError> {
    let layout = StateLayout::working_gas(gas.model);
    let run = pressure_run(gas, u, &layout, first, last, !vars.is_empty())?;
    let cold = run.yhat.len() - 1;
    let mut dp = signals(gas, cold, first, last, |i, k| {
        run.yhat[i][k] - run.yhat[cold][k]
    });
    dp.truncate(cold);
    let sens = vars
        .iter()
        .map(|&v| {
            let scale = gas.vars[v].scale;
            signals(gas, cold, first, last, |i, k| {
                (run.dyhat[i][k][v] - run.dyhat[cold][k][v]) / scale
            })
        })
        .collect();
    Ok((dp, sens))
}

/// A run of the gas stage whose outputs are every CV's pressure (no offsets, no sensor
/// distortion of the outputs: the mechanics feel the true pressures).
fn pressure_run(
    gas: &Stage,
    u: &[f64],
    layout: &StateLayout,
    first: usize,
    last: usize,
    sens: bool,
) -> Result<super::driven::StageRun, FitError> {
    let mut st = gas.clone();
    st.outputs = layout
        .pressures
        .iter()
        .map(|&s| Output {
            channel: String::new(),
            pos: layout.gas_pos(s).expect("gas state"),
            data: Vec::new(),
            sigma: 1.0,
        })
        .collect();
    // offsets still move the prescribed positions, but no output carries them
    for v in &mut st.vars {
        match &mut v.kind {
            VarKind::Offset { out, .. } => *out = usize::MAX,
            VarKind::Sensor(Sensor::Lag { outputs, .. } | Sensor::Gain { outputs, .. }) => {
                outputs.clear()
            }
            _ => {}
        }
    }
    st.run(u, first, last, sens)
}

/// One signal per CV over samples `0..=last` from `value(cv, sample - first)`, held at the
/// first value before `first`.
fn signals(
    gas: &Stage,
    n_cv: usize,
    first: usize,
    last: usize,
    value: impl Fn(usize, usize) -> f64,
) -> Vec<Signal> {
    (0..n_cv)
        .map(|i| {
            let val: Vec<f64> = (0..=last)
                .map(|k| value(i, k.saturating_sub(first)))
                .collect();
            let der = crate::signal::derivative(&val, gas.dt);
            Signal {
                t0: gas.t0,
                dt: gas.dt,
                val,
                der,
            }
        })
        .collect()
}

/// Covariance of stage 1's scaled variables carried in from stage 2's: stage 1 (`mech`, at
/// its optimum `u1` with Jacobian `j1`) reads the pressure differences of stage 2 (`gas` at
/// `u2`, statistics `stats2`) through its derived signals (after the measured ones).
pub fn carried_covariance(
    mech: &Stage,
    u1: &[f64],
    j1: &DMatrix<f64>,
    keep: &[usize],
    gas: &Stage,
    u2: &[f64],
    stats2: &FitStats,
    layout: &StateLayout,
    rec: &Record,
) -> Result<Option<DMatrix<f64>>, FitError> {
    let jtj = j1.transpose() * j1;
    let Some(inv) = jtj.try_inverse() else {
        return Ok(None);
    };
    let (first, last) = rec.tr;
    let residuals_at = |u2: &[f64]| -> Result<Vec<f64>, FitError> {
        let dp = pressure_differences(gas, u2, layout, rec)?;
        let mut st = mech.clone();
        let cold = dp.len() - 1;
        let measured = mech.derived.first().copied().unwrap_or(mech.signals.len());
        st.signals.truncate(measured);
        st.signals.extend(dp.into_iter().take(cold));
        let mut r = st.weighted_residuals(u1, first, last, keep)?;
        r.resize(j1.nrows(), 0.0);
        Ok(r)
    };
    let nv2 = u2.len();
    let mut g = DMatrix::zeros(u1.len(), nv2);
    let values = gas.values(u2);
    use rayon::prelude::*;
    // the central differences are independent runs: in parallel
    let cols = (0..nv2)
        .into_par_iter()
        .map(|k| {
            // relative to the value, so a parameter far below its start stays positive
            let v = &gas.vars[k];
            let h = DU * (values[k].abs() / v.scale.abs().max(1e-300)).clamp(1e-3, 1.0);
            let (mut ua, mut ub) = (u2.to_vec(), u2.to_vec());
            ua[k] -= h;
            ub[k] += h;
            let (ra, rb) = rayon::join(|| residuals_at(&ua), || residuals_at(&ub));
            let (ra, rb) = (ra?, rb?);
            Ok(DVector::from_iterator(
                ra.len(),
                ra.iter().zip(&rb).map(|(a, b)| (b - a) / (2.0 * h)),
            ))
        })
        .collect::<Result<Vec<_>, FitError>>()?;
    for (k, d) in cols.into_iter().enumerate() {
        let col = -(&inv * (j1.transpose() * d));
        g.set_column(k, &col);
    }
    let c2 = scaled_covariance(
        stats2,
        &gas.vars.iter().map(|v| v.scale).collect::<Vec<_>>(),
    );
    Ok(Some(&g * c2 * g.transpose()))
}

/// The covariance of the scaled variables from reported standard errors and correlations.
fn scaled_covariance(stats: &FitStats, scale: &[f64]) -> DMatrix<f64> {
    let k = stats.estimates.len();
    let se: Vec<f64> = stats
        .estimates
        .iter()
        .zip(scale)
        .map(|(e, s)| e.std_error / s.abs().max(1e-300))
        .collect();
    DMatrix::from_fn(k, k, |a, b| {
        let c = stats.correlation[a][b];
        let c = if c.is_finite() {
            c
        } else {
            f64::from(u8::from(a == b))
        };
        c * se[a] * se[b]
    })
}
