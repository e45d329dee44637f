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
//! Gradients are forward sensitivities ([`super::sensitivity`]) on the generated Jacobians.

use nalgebra::{DMatrix, DVector};
use stirling_dsl::Model;

use super::sensitivity::{Column, Driven, Given, Signal};
use super::FitError;
use crate::signal::{derivative, noise_sigma, project_drift, savitzky_golay};
use crate::sim::{integrate, state_scale, Hooks, SimOptions};

/// Lowest ratio of a positive model parameter to its starting value that a stage simulates.
pub const MIN_RATIO: f64 = 0.02;

/// One fit variable.
#[derive(Clone, Debug)]
pub struct Var {
    pub name: String,
    pub initial: f64,
    pub scale: f64,
    pub kind: VarKind,
    /// A log-normal prior centred on `initial`: `ln(value / initial) / prior` is one more
    /// residual (`None`, or `initial = 0`: no prior). See [`super::FitOptions::prior`].
    pub prior: Option<f64>,
}

impl Var {
    /// The variables of the model parameters `free` (indices), scaled by their values.
    pub fn params(model: &dyn Model, p: &[f64], free: &[usize], prior: Option<f64>) -> Vec<Var> {
        free.iter()
            .map(|&j| Var {
                name: model.params()[j].name.into(),
                initial: p[j],
                scale: p[j].abs().max(1e-12),
                kind: VarKind::Param(j),
                prior,
            })
            .collect()
    }

    /// The initial value of free state number `pos`.
    pub fn initial(name: &str, initial: f64, scale: f64, pos: usize) -> Var {
        Var {
            name: name.into(),
            initial,
            scale,
            kind: VarKind::Initial(pos),
            prior: None,
        }
    }

    /// An additive offset of output `out` that moves the prescribed inputs by `du`.
    pub fn offset(name: &str, initial: f64, scale: f64, out: usize, du: Vec<f64>) -> Var {
        Var {
            name: name.into(),
            initial,
            scale,
            kind: VarKind::Offset { out, du },
            prior: None,
        }
    }
}

/// What a fit variable is.
#[derive(Clone, Debug)]
pub enum VarKind {
    /// A model parameter.
    Param(usize),
    /// The initial value of free state number `pos`.
    Initial(usize),
    /// An additive offset of output `out`; `du` (per [`Given`], may be empty) is how the
    /// prescribed inputs move per unit of the offset.
    Offset { out: usize, du: Vec<f64> },
    /// A sensor distortion (see [`Sensor`]); its column is a central difference of two runs.
    Sensor(Sensor),
}

/// A sensor distortion fitted as a variable: the data the stage reads through the sensor as
/// inputs are un-distorted, the model's predictions of what the sensor reads are distorted.
#[derive(Clone, Debug)]
pub enum Sensor {
    /// `measured = (1 + g) true`: the prescribed states `given` (indices into
    /// [`Stage::given`]) are divided by `1 + g`, the outputs `outputs` multiplied by it.
    Gain {
        given: Vec<usize>,
        outputs: Vec<usize>,
    },
    /// `measured = lag(true, tau)` (first order): the input signals `signals` get
    /// `+ tau d/dt` (the inverse lag to first order), the outputs `outputs` are lagged.
    Lag {
        signals: Vec<usize>,
        outputs: Vec<usize>,
    },
}

impl Sensor {
    /// Whether the variable's value cannot be negative (a lag).
    pub fn bounded(&self) -> bool {
        matches!(self, Sensor::Lag { .. })
    }
}

/// A measured output: free state number `pos` plus its offsets.
#[derive(Clone, Debug)]
pub struct Output {
    pub channel: String,
    pub pos: usize,
    pub data: Vec<f64>,
    pub sigma: f64,
}

impl Output {
    /// Output `channel` at free state `pos`, its noise estimated from `data` (at least `floor`).
    pub fn new(channel: &str, pos: usize, data: &[f64], floor: f64) -> Output {
        Output {
            channel: channel.into(),
            pos,
            data: data.to_vec(),
            sigma: noise_sigma(data).max(floor),
        }
    }
}

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
        let th = self.values(u);
        let mut p = self.p.clone();
        let mut z0 = self.z0.clone();
        let mut given = self.given.clone();
        let mut columns = Vec::new();
        let mut col_of = vec![None; self.vars.len()];
        for (k, (v, &val)) in self.vars.iter().zip(&th).enumerate() {
            match &v.kind {
                VarKind::Param(i) => {
                    if sens && v.initial > 0.0 && val < MIN_RATIO * v.initial {
                        // a positive parameter far below its start (a regenerator resistance
                        // near zero) makes the model arbitrarily stiff: refuse the trial
                        // point instead of integrating it for minutes (optimizer steps only:
                        // they are the runs with sensitivities)
                        return Err(FitError::ParamRange {
                            name: v.name.clone(),
                            value: val,
                            floor: MIN_RATIO * v.initial,
                        });
                    }
                    p[*i] = val;
                    col_of[k] = Some(columns.len());
                    columns.push(Column::Param {
                        index: *i,
                        scale: v.scale,
                    });
                }
                VarKind::Initial(pos) => {
                    z0[*pos] = val;
                    col_of[k] = Some(columns.len());
                    columns.push(Column::Initial {
                        pos: *pos,
                        scale: v.scale,
                    });
                }
                VarKind::Offset { du, .. } => {
                    if !du.is_empty() {
                        for (g, d) in given.iter_mut().zip(du) {
                            g.constant += d * val;
                        }
                        col_of[k] = Some(columns.len());
                        columns.push(Column::Input {
                            du: du.clone(),
                            scale: v.scale,
                        });
                    }
                }
                VarKind::Sensor(_) => {}
            }
        }
        if !sens {
            columns.clear();
        }
        let t_start = self.t0 + first as f64 * self.dt;
        let mut signals: Vec<Signal> = self
            .signals
            .iter()
            .map(|s| Signal {
                t0: s.t0 - t_start,
                ..s.clone()
            })
            .collect();
        let (gain, lag) = self.apply_sensors(&th, &mut given, &mut signals);
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
        let x0 = sys.initial(&z0);
        let samples: Vec<f64> = (0..=last - first).map(|k| k as f64 * self.dt).collect();
        let t_end = samples[samples.len() - 1].max(self.dt);
        let sim = if std::env::var_os("STIRLING_DENSE_SENS").is_none() && sys.columns.len() >= 2 {
            // block-diagonal Newton matrix: the sparse LU factors the blocks one by one
            SimOptions {
                linear_solver: crate::sim::LinearSolverKind::Sparse,
                ..self.sim
            }
        } else {
            self.sim
        };
        let traj = integrate(&sys, &x0, t_end, &samples, &sim, Hooks::default())
            .map_err(|e| FitError::Sim(self.name.to_string(), e.to_string()))?;
        let nz = self.free.len();
        let mut yhat = vec![Vec::new(); self.outputs.len()];
        let mut dyhat = vec![Vec::new(); self.outputs.len()];
        for row in &traj.x {
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

    /// Apply the sensor variables at values `th`: scale the prescribed states read through a
    /// gain, un-lag the input signals read through a lag; returns each output's gain factor
    /// and lag time constant.
    fn apply_sensors(
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
    fn sensor_columns(
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

    /// How the noise on the prescribed inputs moves the weighted residuals, by Monte Carlo:
    /// `draws` noise records (the estimated standard deviation, white, smoothed like the
    /// signal) are added to the inputs; each gives the change `dr` of the residuals on `keep`
    /// (the drift band projected out as in the fit). Empty without input noise.
    pub fn input_noise_draws(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        keep: &[usize],
        draws: usize,
        seed: u64,
    ) -> Result<Vec<Vec<f64>>, FitError> {
        use rand::{rngs::StdRng, Rng, SeedableRng};
        if self.input_noise.is_empty() || draws == 0 {
            return Ok(Vec::new());
        }
        let base = self.run(u, first, last, false)?;
        let mut rng = StdRng::seed_from_u64(seed);
        let mut gauss = move || {
            let u1: f64 = 1.0 - rng.gen::<f64>();
            let u2: f64 = rng.gen::<f64>();
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        };
        let mut noisy = Stage {
            input_noise: Vec::new(),
            ..self.clone()
        };
        let mut out = Vec::with_capacity(draws);
        for _ in 0..draws {
            for &(s, sd, h) in &self.input_noise {
                let e: Vec<f64> = (0..self.signals[s].val.len())
                    .map(|_| sd * gauss())
                    .collect();
                let (ev, ed) = savitzky_golay(&e, self.dt, h, 4);
                let sig = &mut noisy.signals[s];
                for k in 0..ev.len() {
                    sig.val[k] = self.signals[s].val[k] + ev[k];
                    sig.der[k] = self.signals[s].der[k] + ed[k];
                }
            }
            let run = noisy.run(u, first, last, false)?;
            let mut dr = Vec::with_capacity(keep.len() * self.outputs.len());
            for (o, out) in self.outputs.iter().enumerate() {
                let start = dr.len();
                for &i in keep {
                    let k = i - first;
                    dr.push((run.yhat[o][k] - base.yhat[o][k]) / out.sigma);
                }
                if self.drift > 0 {
                    project_drift(&mut dr[start..], self.drift);
                }
            }
            // the priors do not see the input noise
            dr.resize(dr.len() + super::prior::prior_count(&self.vars), 0.0);
            out.push(dr);
        }
        Ok(out)
    }

    /// Covariance of the fit variables `u` caused by the noise on the prescribed inputs
    /// (errors in variables): each draw of [`Stage::input_noise_draws`] moves the first-order
    /// estimate by `-(J^T J)^-1 J^T dr`; returns the sample covariance of those moves (`None`
    /// without input noise).
    pub fn input_noise_cov(
        &self,
        u: &[f64],
        first: usize,
        last: usize,
        keep: &[usize],
        j: &DMatrix<f64>,
        draws: usize,
        seed: u64,
    ) -> Result<Option<DMatrix<f64>>, FitError> {
        let nv = self.vars.len();
        let Some(inv) = (j.transpose() * j).try_inverse() else {
            return Ok(None);
        };
        let drs = self.input_noise_draws(u, first, last, keep, draws, seed)?;
        if drs.is_empty() {
            return Ok(None);
        }
        let mut acc = DMatrix::zeros(nv, nv);
        for dr in &drs {
            let du = &inv * (j.transpose() * DVector::from_column_slice(dr));
            acc += &du * du.transpose();
        }
        Ok(Some(acc / drs.len() as f64))
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
        Ok(r)
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

/// Lag every sensitivity column (`rows[sample][var]`) by the first-order filter.
fn lag_columns(rows: &mut [Vec<f64>], dt: f64, tau: f64) {
    let nv = rows.first().map_or(0, |r| r.len());
    for v in 0..nv {
        let col: Vec<f64> = rows.iter().map(|r| r[v]).collect();
        let f = crate::signal::first_order_lag(&col, dt, tau);
        rows.iter_mut().zip(f).for_each(|(r, c)| r[v] = c);
    }
}

/// Weight of the cold-side channel in the prescribed pressure of CV `i` of `ncv` (hot = 0).
pub fn cold_weight(i: usize, ncv: usize, have_hot: bool) -> f64 {
    if !have_hot || ncv < 2 {
        1.0
    } else {
        i as f64 / (ncv - 1) as f64
    }
}

/// Static shift of the body positions per unit pressure offset on the cold and hot channels:
/// `dq = -J_aq^-1 J_aP off` (rows: the velocity equations; columns: positions, pressures).
pub fn static_shift(
    model: &dyn Model,
    p: &[f64],
    have_hot: bool,
) -> Result<[Vec<f64>; 2], FitError> {
    let n = model.n_states();
    let mut eq = vec![0.0; n];
    model.equilibrium_guess(p, &mut eq);
    let j = model.jacobian_dense(p, &eq, 0.0);
    let layout = crate::layout::StateLayout::of(model);
    let (pos, vel, ps) = (&layout.positions, &layout.velocities, &layout.pressures);
    let jaq = DMatrix::from_fn(vel.len(), pos.len(), |r, c| j[vel[r] + n * pos[c]]);
    let lu = jaq.lu();
    let mut out = [Vec::new(), Vec::new()];
    for (ch, o) in out.iter_mut().enumerate() {
        let rhs = DVector::from_fn(vel.len(), |r, _| {
            ps.iter()
                .enumerate()
                .map(|(i, &pi)| {
                    let wc = cold_weight(i, ps.len(), have_hot);
                    j[vel[r] + n * pi] * if ch == 0 { wc } else { 1.0 - wc }
                })
                .sum::<f64>()
        });
        let dq = lu.solve(&(-rhs)).ok_or_else(|| {
            FitError::Bad("the static stiffness of the bodies is singular".into())
        })?;
        *o = dq.iter().copied().collect();
    }
    Ok(out)
}
