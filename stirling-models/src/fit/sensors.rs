//! Sensor distortions fitted as stage variables: a position gain scales what the stage reads
//! and predicts, a pressure lag un-lags the inputs and lags the predictions.

use super::driven::Stage;
use super::sensitivity::{Given, Signal};
use super::vars::{Sensor, VarKind};
use super::FitError;
use crate::signal::{derivative, first_order_lag};

impl Stage<'_> {
    /// Apply the sensor variables at values `th`: scale the prescribed states read through a
    /// gain, un-lag the input signals read through a lag; returns each output's gain factor
    /// and lag time constant.
    pub(super) fn apply_sensors(
        &self,
        th: &[f64],
        given: &mut [Given],
        signals: &mut [Signal],
    ) -> (Vec<f64>, Vec<f64>) {
        let mut gain = vec![1.0; self.outputs.len()];
        let mut lag = vec![0.0; self.outputs.len()];
        for (v, &val) in self.vars.iter().zip(th) {
            match &v.kind {
                VarKind::Sensor(Sensor::Gain { given: gs, outputs }) => {
                    for &g in gs {
                        let gv = &mut given[g];
                        gv.constant /= 1.0 + val;
                        gv.terms.iter_mut().for_each(|t| t.1 /= 1.0 + val);
                    }
                    outputs.iter().for_each(|&o| gain[o] *= 1.0 + val);
                }
                VarKind::Sensor(Sensor::Lag {
                    signals: ss,
                    outputs,
                }) => {
                    for &s in ss {
                        let sig = &mut signals[s];
                        let d2 = derivative(&sig.der, sig.dt);
                        for k in 0..sig.val.len() {
                            sig.val[k] += val * sig.der[k];
                            sig.der[k] += val * d2[k];
                        }
                    }
                    outputs.iter().for_each(|&o| lag[o] += val);
                }
                _ => {}
            }
        }
        (gain, lag)
    }

    /// Columns of the sensor variables by differences of two runs (central; forward where
    /// a lag would go negative).
    pub(super) fn sensor_columns(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        dyhat: &mut [Vec<Vec<f64>>],
    ) -> Result<(), FitError> {
        const DU: f64 = 0.02;
        for (k, v) in self.vars.iter().enumerate() {
            let VarKind::Sensor(s) = &v.kind else {
                continue;
            };
            if v.scale == 0.0 {
                // a value the stage is given, not fitted (a cut gain: `diagnose::joint`)
                dyhat.iter_mut().flatten().for_each(|row| row[k] = 0.0);
                continue;
            }
            let val = v.initial + v.scale * u[k];
            let lo = if s.bounded() && val - DU * v.scale < 0.0 {
                u[k]
            } else {
                u[k] - DU
            };
            let (mut ua, mut ub) = (u.to_vec(), u.to_vec());
            ua[k] = lo;
            ub[k] = u[k] + DU;
            let (ra, rb) = (
                self.run(&ua, first, last, false)?,
                self.run(&ub, first, last, false)?,
            );
            for (o, rows) in dyhat.iter_mut().enumerate() {
                for (i, row) in rows.iter_mut().enumerate() {
                    row[k] = (rb.yhat[o][i] - ra.yhat[o][i]) / (ub[k] - ua[k]);
                }
            }
        }
        Ok(())
    }
}

/// Lag every sensitivity column (`rows[sample][var]`) by the first-order filter.
pub(super) fn lag_columns(rows: &mut [Vec<f64>], dt: f64, tau: f64) {
    let nv = rows.first().map_or(0, |r| r.len());
    for v in 0..nv {
        let col: Vec<f64> = rows.iter().map(|r| r[v]).collect();
        let f = first_order_lag(&col, dt, tau);
        rows.iter_mut().zip(f).for_each(|(r, c)| r[v] = c);
    }
}
