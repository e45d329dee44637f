//! The gas's uncertainty carried into the flywheel's estimates (stage 1 of a kinematic
//! engine, `flywheel.rs`): the torque balance reads the torque of the gas that stage 2 fitted,
//! and the displacer's share of it (the regenerator's pressure drop on the displacer's faces)
//! is set by gas parameters the record hardly determines (`Rf`'s interval on the gamma LTD is
//! +-80 %). Without this part, freeing `Rf` beside the friction left `T_friction` at 9.4e-5
//! +- 2.6e-6 against a truth of 1.18e-4.
//!
//! Each of stage 2's variables is moved by one standard error either way (at most half its
//! value), the gas rerun and
//! the flywheel's (linear) estimate redone: the central differences `G` give the covariance
//! `G C G^T`, `C` stage 2's (standard errors and correlations).

use nalgebra::DMatrix;
use stirling_dsl::Model;

use super::flywheel::{least_squares, rows, Samples};
use crate::fit::report::FitStats;
use crate::fit::stage_fit::FittedStage;
use crate::fit::vars::VarKind;
use crate::fit::FitError;

/// Where the torque balance looks: the training block after the burn-in, its measured
/// acceleration, the speed state and the flywheel's free parameters.
pub struct Balance<'b> {
    pub first: usize,
    pub last: usize,
    pub acc: &'b [f64],
    pub t0: f64,
    pub dt: f64,
    pub speed: usize,
    pub mech: &'b [usize],
}

impl Balance<'_> {
    /// The flywheel's estimate with the gas at stage 2's variables `u` (one Gauss-Newton
    /// step from `p`: the friction torques are linear); `None` when the step cannot be taken.
    fn estimate(
        &self,
        model: &dyn Model,
        p: &[f64],
        gas: &FittedStage,
        u: &[f64],
    ) -> Result<Option<Vec<f64>>, FitError> {
        let mut p = p.to_vec();
        for (v, val) in gas.stage.vars.iter().zip(gas.stage.values(u)) {
            if let VarKind::Param(j) = v.kind {
                p[j] = val;
            }
        }
        let x = gas.stage.full_states(u, gas.first, self.last)?;
        let s = Samples {
            x: x[self.first - gas.first..].to_vec(),
            acc: self.acc[self.first..=self.last].to_vec(),
            t: (self.first..=self.last)
                .map(|k| self.t0 + k as f64 * self.dt)
                .collect(),
        };
        let (r, jm) = rows(model, &p, self.speed, &s, self.mech);
        Ok(least_squares(&jm, &r).map(|d| {
            self.mech
                .iter()
                .zip(d.iter())
                .map(|(&j, d)| p[j] + d)
                .collect()
        }))
    }

    /// The covariance of the flywheel's estimates from stage 2's (`stats`), at the flywheel's
    /// fitted parameters `p`. A variable whose move cannot be integrated adds nothing (said
    /// by `skipped`).
    pub fn gas_cov(
        &self,
        model: &dyn Model,
        p: &[f64],
        gas: &FittedStage,
        stats: &FitStats,
    ) -> Result<(DMatrix<f64>, Vec<String>), FitError> {
        let vars = &gas.stage.vars;
        let k = self.mech.len();
        let mut g = DMatrix::zeros(k, vars.len());
        let mut se = vec![0.0; vars.len()];
        let mut skipped = Vec::new();
        for (i, v) in vars.iter().enumerate() {
            let Some(e) = stats.estimates.iter().find(|e| e.name == v.name) else {
                continue;
            };
            if !(e.std_error > 0.0 && e.std_error.is_finite()) {
                continue;
            }
            // a standard error, or half the value when that is less (a resistance of 4.9e3
            // +- 6.9e3 moved by a whole error would be negative)
            let step = if e.value != 0.0 {
                e.std_error.min(0.5 * e.value.abs())
            } else {
                e.std_error
            };
            let h = step / v.scale;
            let mut moved = [gas.u.clone(), gas.u.clone()];
            moved[0][i] += h;
            moved[1][i] -= h;
            let up = self.estimate(model, p, gas, &moved[0]).ok().flatten();
            let down = self.estimate(model, p, gas, &moved[1]).ok().flatten();
            let (Some(up), Some(down)) = (up, down) else {
                skipped.push(v.name.clone());
                continue;
            };
            for c in 0..k {
                g[(c, i)] = (up[c] - down[c]) / (2.0 * step);
            }
            se[i] = e.std_error;
        }
        let names: Vec<&str> = stats.estimates.iter().map(|e| e.name.as_str()).collect();
        let at = |name: &str| names.iter().position(|n| *n == name);
        let c = DMatrix::from_fn(vars.len(), vars.len(), |a, b| {
            match (at(&vars[a].name), at(&vars[b].name)) {
                (Some(ia), Some(ib)) if stats.correlation[ia][ib].is_finite() => {
                    se[a] * se[b] * stats.correlation[ia][ib]
                }
                _ => 0.0,
            }
        });
        Ok((&g * c * g.transpose(), skipped))
    }
}
