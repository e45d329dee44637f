//! The seed's two driven subsystems (its Figures 3-5):
//! - stage 1, mechanics: the body states integrated with the pressure states prescribed from
//!   the measured pressures (`p` on the cold side, `p_hot` on the hot side, sections in
//!   between interpolated linearly); fitted: the free mechanical parameters, the initial body
//!   states, the position offsets (which also absorb the static shift caused by any pressure
//!   offset, since a constant force only moves the mean position);
//! - stage 2, gas: the gas states integrated with the body states prescribed from the measured
//!   positions (offsets removed) and velocities from a smoothing (Savitzky-Golay, quartic)
//!   derivative; fitted: the free gas parameters and the pressure offsets. A pressure offset
//!   also moves the stage-1 position offsets by the static response `-J_qq^-1 J_qP off`, so the
//!   prescribed positions depend on it and its sensitivity column carries that input term.
//!
//! Gradients are forward sensitivities ([`crate::fit::sensitivity`]) on the generated Jacobians.

use nalgebra::DMatrix;
use stirling_dsl::Model;

use super::sensitivity::{Column, Driven, Given, Signal};
use super::sensors::lag_columns;
use super::vars::{Output, Var, VarKind, MIN_RATIO};
use super::FitError;
use crate::signal::project_drift;
use crate::sim::{state_scale, SimOptions};

/// A driven-subsystem fitting problem on a uniform record.
#[derive(Clone)]
pub struct Stage<'a> {
    pub name: &'static str,
    pub model: &'a dyn Model,
    pub p: Vec<f64>,
    pub base: Vec<f64>,
    pub free: Vec<usize>,
    pub given: Vec<Given>,
    pub signals: Vec<Signal>,
    pub z0: Vec<f64>,
    pub vars: Vec<Var>,
    pub outputs: Vec<Output>,
    /// Record time of sample 0 and the interval.
    pub t0: f64,
    pub dt: f64,
    pub sim: SimOptions,
    /// Sub-cycle drift projected out of every output's residuals: the cosines
    /// `cos(pi k (i + 1/2) / N)`, `k = 1..=drift`, on the `N` kept samples (0: none).
    ///
    /// Why: noise on a prescribed input is integrated by the driven subsystem (the power
    /// piston, far below its running frequency, answers a slow force by `F / kp`), so the
    /// model output carries a slow random wander the data do not have; least squares then
    /// bends the parameters that set the low-frequency gain (`kp`) to suppress it
    /// (errors-in-variables bias). Projecting the band below the running frequency out of the
    /// residuals (and of the Jacobian) removes that band from the criterion; the mean stays
    /// (carried by the offsets). The projection is exact least squares with `drift` nuisance
    /// coefficients per output, so the statistics lose `drift` degrees of freedom per output.
    pub drift: usize,
    /// Noise on the prescribed inputs: `(signal, standard deviation of the raw samples,
    /// Savitzky-Golay half-width the signal was smoothed with)`; see [`Stage::input_noise_cov`].
    pub input_noise: Vec<(usize, f64, usize)>,
    /// Signals the model computed (the pressure differences of [`super::unmeasured`]), not
    /// measured: a sensor effect does not act on them.
    pub derived: Vec<usize>,
    /// Restarts of the integration from the measured state (`None`: one run over the window).
    pub restarts: Option<super::restarts::Restarts>,
}

/// What a run is built from at given variable values.
struct Prepared {
    p: Vec<f64>,
    z0: Vec<f64>,
    given: Vec<super::sensitivity::Given>,
    columns: Vec<Column>,
    col_of: Vec<Option<usize>>,
}

impl Prepared {
    /// Give variable `k` the next sensitivity column, `c`.
    fn column(&mut self, k: usize, c: Column) {
        self.col_of[k] = Some(self.columns.len());
        self.columns.push(c);
    }
}

/// A positive parameter far below its start (a regenerator resistance near zero) makes the
/// model arbitrarily stiff: refuse the trial point instead of integrating it for minutes
/// (checked on optimizer steps only: they are the runs with sensitivities); and a trial
/// outside the parameter's bounds (the optimizer then takes a shorter step).
fn check_floor(v: &Var, val: f64) -> Result<(), FitError> {
    super::vars::check_within(&v.name, val, v.bounds)?;
    if v.initial > 0.0 && val < MIN_RATIO * v.initial {
        return Err(FitError::ParamRange {
            name: v.name.clone(),
            value: val,
            floor: MIN_RATIO * v.initial,
        });
    }
    Ok(())
}

/// Set variable `v` to `val` in `pr`; its sensitivity column, if it has one.
fn set_var(pr: &mut Prepared, v: &Var, val: f64, trial: bool) -> Result<Option<Column>, FitError> {
    Ok(match &v.kind {
        VarKind::Param(i) => {
            if trial {
                check_floor(v, val)?;
            }
            pr.p[*i] = val;
            Some(Column::Param {
                index: *i,
                scale: v.scale,
            })
        }
        VarKind::Initial(pos) => {
            pr.z0[*pos] = val;
            Some(Column::Initial {
                pos: *pos,
                scale: v.scale,
            })
        }
        VarKind::Offset { du, .. } => {
            if du.is_empty() {
                None
            } else {
                for (g, d) in pr.given.iter_mut().zip(du) {
                    g.constant += d * val;
                }
                Some(Column::Input {
                    du: du.clone(),
                    scale: v.scale,
                })
            }
        }
        VarKind::Sensor(_) => None,
        VarKind::Linked { pairs, at } => {
            for &(g, s) in pairs {
                pr.given[g].terms.push((s, val - at, false));
            }
            Some(Column::Signals {
                pairs: pairs.clone(),
                scale: v.scale,
            })
        }
    })
}

/// Simulated outputs (rows: samples of the window) and their derivatives.
pub struct StageRun {
    /// Sample indices of the window.
    pub first: usize,
    pub yhat: Vec<Vec<f64>>,
    /// `dyhat[o][k][v]`: output `o`, sample `k`, variable `v` (empty without sensitivities).
    pub dyhat: Vec<Vec<Vec<f64>>>,
}

impl Stage<'_> {
    /// Values of the variables at `u`.
    pub fn values(&self, u: &[f64]) -> Vec<f64> {
        self.vars
            .iter()
            .zip(u)
            .map(|(v, u)| v.initial + v.scale * u)
            .collect()
    }

    /// Simulate sample indices `first..last` (inclusive), with sensitivities if asked.
    pub fn run(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        sens: bool,
    ) -> Result<StageRun, FitError> {
        self.run_checked(u, first, last, sens, sens)
    }

    /// [`Stage::run`]; `trial`: an optimizer's trial point, whose positive parameters must
    /// stay above their floor ([`check_floor`]).
    fn run_checked(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        sens: bool,
        trial: bool,
    ) -> Result<StageRun, FitError> {
        let th = self.values(u);
        let (sys, z0, (gain, lag), col_of) = self.system(&th, first, trial, sens)?;
        let rows = match &self.restarts {
            Some(r) if r.every < last - first => {
                self.integrate_restarted(&sys, &z0, (first, last), r, &gain)?
            }
            _ => self.integrate_window(&sys, &z0, last - first)?,
        };
        let (mut yhat, mut dyhat) = self.outputs_of(&rows, &th, &gain, &col_of, sens);
        for (o, &tau) in lag.iter().enumerate() {
            if tau > 0.0 {
                yhat[o] = crate::signal::first_order_lag(&yhat[o], self.dt, tau);
                lag_columns(&mut dyhat[o], self.dt, tau);
            }
        }
        if sens {
            self.sensor_columns(u, first, last, &mut dyhat)?;
        }
        Ok(StageRun { first, yhat, dyhat })
    }

    /// The full model state (free states simulated, prescribed ones from their signals) at
    /// every sample `first..=last`, at the variables `u`, without sensitivities (the
    /// flywheel's torque balance of a kinematic engine reads the gas it drives from here).
    pub fn full_states(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
    ) -> Result<Vec<Vec<f64>>, FitError> {
        let (sys, z0, ..) = self.system(&self.values(u), first, false, false)?;
        let rows = self.integrate_window(&sys, &z0, last - first)?;
        Ok(rows
            .iter()
            .enumerate()
            .map(|(k, z)| sys.full_state(k as f64 * self.dt, &z[..self.free.len()]))
            .collect())
    }

    /// The driven system at the variable values `th` from sample `first` (sensitivity
    /// columns when `sens`), its initial free states, the sensors' gains and lags, and the
    /// column of each variable.
    #[allow(clippy::type_complexity)]
    fn system(
        &self,
        th: &[f64],
        first: usize,
        trial: bool,
        sens: bool,
    ) -> Result<
        (
            Driven<'_>,
            Vec<f64>,
            (Vec<f64>, Vec<f64>),
            Vec<Option<usize>>,
        ),
        FitError,
    > {
        let Prepared {
            p,
            z0,
            mut given,
            mut columns,
            col_of,
        } = self.prepare(th, trial)?;
        if !sens {
            columns.clear();
        }
        let mut signals = self.signals_from(first);
        let sensors = self.apply_sensors(th, &mut given, &mut signals);
        let zscale: Vec<f64> = {
            let s = state_scale(self.model, &p);
            self.free.iter().map(|&i| s[i]).collect()
        };
        let sys = Driven {
            model: self.model,
            p,
            base: self.base.clone(),
            free: self.free.clone(),
            given,
            signals,
            columns,
            zscale,
        };
        Ok((sys, z0, sensors, col_of))
    }

    /// The prescribed signals with their time origin moved to sample `first`.
    fn signals_from(&self, first: usize) -> Vec<Signal> {
        let t_start = self.t0 + first as f64 * self.dt;
        self.signals
            .iter()
            .map(|s| Signal {
                t0: s.t0 - t_start,
                ..s.clone()
            })
            .collect()
    }

    /// Integrate `sys` from the free states `z0` over `steps` samples; the rows at the samples.
    pub(super) fn integrate_window(
        &self,
        sys: &Driven,
        z0: &[f64],
        steps: usize,
    ) -> Result<Vec<Vec<f64>>, FitError> {
        let samples: Vec<f64> = (0..=steps).map(|k| k as f64 * self.dt).collect();
        let t_end = samples[samples.len() - 1].max(self.dt);
        sys.integrate(z0, t_end, &samples, &self.sim)
            .map_err(|source| FitError::Sim {
                stage: self.name.to_string(),
                source,
            })
    }

    /// The model parameters, initial free states, prescribed states and sensitivity columns
    /// at the variable values `th` (with the column of each variable, if it has one);
    /// `trial`: check the parameter floors.
    fn prepare(&self, th: &[f64], trial: bool) -> Result<Prepared, FitError> {
        let mut pr = Prepared {
            p: self.p.clone(),
            z0: self.z0.clone(),
            given: self.given.clone(),
            columns: Vec::new(),
            col_of: vec![None; self.vars.len()],
        };
        for (k, (v, &val)) in self.vars.iter().zip(th).enumerate() {
            if let Some(c) = set_var(&mut pr, v, val, trial)? {
                pr.column(k, c);
            }
        }
        Ok(pr)
    }

    /// Outputs (gain and offsets applied) and their sensitivities from the rows of a run.
    fn outputs_of(
        &self,
        rows: &[Vec<f64>],
        th: &[f64],
        gain: &[f64],
        col_of: &[Option<usize>],
        sens: bool,
    ) -> (Vec<Vec<f64>>, Vec<Vec<Vec<f64>>>) {
        let nz = self.free.len();
        let mut yhat = vec![Vec::new(); self.outputs.len()];
        let mut dyhat = vec![Vec::new(); self.outputs.len()];
        for row in rows {
            for (o, out) in self.outputs.iter().enumerate() {
                let mut y = gain[o] * row[out.pos];
                let mut d = vec![0.0; if sens { self.vars.len() } else { 0 }];
                for (k, v) in self.vars.iter().enumerate() {
                    if let VarKind::Offset { out: oo, .. } = v.kind {
                        if oo == o {
                            y += th[k];
                            if sens {
                                d[k] += v.scale;
                            }
                        }
                    }
                    if sens {
                        if let Some(c) = col_of[k] {
                            d[k] += gain[o] * row[nz + c * nz + out.pos];
                        }
                    }
                }
                yhat[o].push(y);
                if sens {
                    dyhat[o].push(d);
                }
            }
        }
        (yhat, dyhat)
    }

    /// Weighted residuals on the sample indices `keep` (within `first..=last`), drift
    /// projected, without the prior rows and without sensitivities.
    pub fn weighted_residuals(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        keep: &[usize],
    ) -> Result<Vec<f64>, FitError> {
        let run = self.run(u, first, last, false)?;
        Ok(self.output_residuals(&run, first, keep))
    }

    /// The residuals of [`Stage::residuals`] (with the prior rows) without the Jacobian: an
    /// optimizer's trial point, tested before its sensitivities are computed (the parameter
    /// floors are checked as in [`Stage::residuals`]).
    pub fn trial_residuals(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        keep: &[usize],
    ) -> Result<Vec<f64>, FitError> {
        let run = self.run_checked(u, first, last, false, true)?;
        let mut r = self.output_residuals(&run, first, keep);
        r.extend(super::prior::prior_rows(&self.vars, u).iter().map(|p| p.r));
        Ok(r)
    }

    /// Every output's weighted, drift-projected residuals of a run on the samples `keep`.
    fn output_residuals(&self, run: &StageRun, first: usize, keep: &[usize]) -> Vec<f64> {
        let mut r = Vec::with_capacity(keep.len() * self.outputs.len());
        for (o, out) in self.outputs.iter().enumerate() {
            let start = r.len();
            r.extend(
                keep.iter()
                    .map(|&i| (run.yhat[o][i - first] - out.data[i]) / out.sigma),
            );
            if self.drift > 0 {
                project_drift(&mut r[start..], self.drift);
            }
        }
        r
    }

    /// Weighted residuals and Jacobian on the sample indices `keep` (within `first..=last`):
    /// every output's samples in turn, then the prior rows ([`super::prior`]).
    pub fn residuals(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        keep: &[usize],
    ) -> Result<(Vec<f64>, DMatrix<f64>), FitError> {
        let run = self.run(u, first, last, true)?;
        let nv = self.vars.len();
        let priors = super::prior::prior_rows(&self.vars, u);
        let rows = keep.len() * self.outputs.len() + priors.len();
        let mut r = Vec::with_capacity(rows);
        let mut j = DMatrix::zeros(rows, nv);
        let mut row = 0;
        for (o, out) in self.outputs.iter().enumerate() {
            let start = row;
            for &i in keep {
                let k = i - first;
                r.push((run.yhat[o][k] - out.data[i]) / out.sigma);
                for v in 0..nv {
                    j[(row, v)] = run.dyhat[o][k][v] / out.sigma;
                }
                row += 1;
            }
            if self.drift > 0 {
                project_drift(&mut r[start..row], self.drift);
                for v in 0..nv {
                    let mut col: Vec<f64> = (start..row).map(|i| j[(i, v)]).collect();
                    project_drift(&mut col, self.drift);
                    for (i, c) in (start..row).zip(col) {
                        j[(i, v)] = c;
                    }
                }
            }
        }
        for pr in priors {
            r.push(pr.r);
            j[(row, pr.var)] = pr.dr_du;
            row += 1;
        }
        Ok((r, j))
    }
}
