//! Multiple-shooting refinement: the training block is cut into segments of a few cycles, each
//! simulated freely (nothing prescribed) from its own initial state; the weighted output error
//! of all segments is minimised jointly over the free model parameters, the sensor offsets and
//! every segment's initial state, by [`super::lm`].
//!
//! Why: a self-excited oscillator drifts in phase over a long free run, so a single-shooting
//! output error is dominated by the drift; over segments of about two cycles it is not, and the
//! free segment states absorb the state noise.
//!
//! The Jacobian comes from forward sensitivities of each free segment, `S' = f_x S + f_p` with
//! `S(0) = [I | 0]` (columns: initial states, then parameters), integrated as a
//! [`Driven`] system with every state free. The segment joins are not constrained: their
//! mismatch (the defects, in units of each state's scale) is reported as a consistency check.
//!
//! Cost: each segment integrates `n (1 + n + free)` states with a dense Jacobian, so the
//! refinement suits the small models (`cv1`: 0.3 s on 0.5 s of data); on `nsection` n = 2
//! (11 states) it takes minutes in the dev profile, and the fast gas modes (pressure
//! differences along the regenerator, mass shares) make the segments' gas initial states
//! nearly collinear (reported in the warnings) although the model parameters stay separable.

use std::time::Instant;

use nalgebra::DMatrix;
use serde::Serialize;
use stirling_dsl::{Model, StateKind};

use super::free_run::{channels, measured_state, SensorOffsets};
use super::report::{self, fit_percent, ChannelFit, FitStats};
use super::sensitivity::{Column, Driven};
use super::{lm, FitError};
use crate::data::Measured;
use crate::signal::noise_sigma;
use crate::sim::{integrate, state_scale, Hooks, SimOptions};

/// Options of the refinement.
#[derive(Clone, Copy, Debug)]
pub struct MsOptions {
    /// Cycles per segment.
    pub cycles: f64,
    /// Longest span of the training block used, from its start (s); keeps the cost bounded.
    pub span: f64,
    /// Fit the sensor offsets too (otherwise they stay at their given values).
    pub offsets: bool,
    /// Half-width of the smoothing window for the initial states (s).
    pub smooth: f64,
    pub lm: lm::LmOptions,
    pub sim: SimOptions,
}

impl Default for MsOptions {
    fn default() -> Self {
        Self {
            cycles: 2.0,
            span: 0.5,
            offsets: true,
            smooth: 0.006,
            lm: lm::LmOptions {
                max_iter: 30,
                ftol: 1e-8,
                xtol: 1e-7,
                lambda0: 1e-3,
                max_step: f64::INFINITY,
            },
            sim: SimOptions {
                rtol: 1e-7,
                atol: 1e-7,
                ..Default::default()
            },
        }
    }
}

/// One segment.
#[derive(Clone, Debug, Serialize)]
pub struct Segment {
    pub t0: f64,
    pub t1: f64,
    /// Largest `|x_end(previous) - x0(this)| / scale` over the states (0 for the first).
    pub defect: f64,
}

/// The refinement's result.
#[derive(Clone, Debug, Serialize)]
pub struct MultipleShooting {
    /// Estimates of the model parameters, offsets and segment initial states (`seg<k>.<state>`).
    pub stats: FitStats,
    /// All model parameters after the refinement.
    pub params: Vec<(String, f64)>,
    pub offsets: SensorOffsets,
    pub segments: Vec<Segment>,
    /// Fit per channel over the segments (block `segments`).
    pub fits: Vec<ChannelFit>,
    pub iterations: usize,
    pub evaluations: usize,
    pub converged: bool,
    pub seconds: f64,
}

impl MultipleShooting {
    pub fn estimate(&self, name: &str) -> Option<&report::Estimate> {
        self.stats.estimates.iter().find(|e| e.name == name)
    }
}

struct Var {
    name: String,
    initial: f64,
    scale: f64,
}

struct Problem<'a> {
    model: &'a dyn Model,
    p: Vec<f64>,
    free: Vec<usize>,
    /// `(name, state, data, sigma, offset variable)`.
    outs: Vec<(String, usize, Vec<f64>, f64, Option<usize>)>,
    off0: Vec<f64>,
    /// Sample ranges `[a, b]` (b is the next segment's a).
    segs: Vec<(usize, usize)>,
    vars: Vec<Var>,
    n_off: usize,
    dt: f64,
    zscale: Vec<f64>,
    sim: SimOptions,
}

struct Eval {
    r: Vec<f64>,
    j: DMatrix<f64>,
    yhat: Vec<Vec<f64>>,
    ends: Vec<Vec<f64>>,
}

impl Problem<'_> {
    fn values(&self, u: &[f64]) -> Vec<f64> {
        self.vars
            .iter()
            .zip(u)
            .map(|(v, u)| v.initial + v.scale * u)
            .collect()
    }

    fn eval(&self, u: &[f64], sens: bool) -> Result<Eval, FitError> {
        let th = self.values(u);
        let (np, no, n) = (self.free.len(), self.n_off, self.model.n_states());
        let mut p = self.p.clone();
        for (k, &j) in self.free.iter().enumerate() {
            p[j] = th[k];
        }
        let mut columns: Vec<Column> = Vec::new();
        if sens {
            for s in 0..n {
                columns.push(Column::Initial {
                    pos: s,
                    scale: self.vars[np + no + s].scale,
                });
            }
            for (k, &j) in self.free.iter().enumerate() {
                columns.push(Column::Param {
                    index: j,
                    scale: self.vars[k].scale,
                });
            }
        }
        let nvar = self.vars.len();
        let rows: usize = self.segs.iter().map(|(a, b)| b - a).sum::<usize>() + 1;
        let rows = rows * self.outs.len();
        let mut r = vec![0.0; rows];
        let mut jm = DMatrix::zeros(if sens { rows } else { 0 }, nvar);
        let mut yhat = vec![Vec::new(); self.outs.len()];
        let mut ends = Vec::new();
        let nseg = self.segs.len();
        let total = rows / self.outs.len();
        let mut row0 = 0;
        for (s, &(a, b)) in self.segs.iter().enumerate() {
            let base = np + no + s * n;
            let z0 = th[base..base + n].to_vec();
            let sys = Driven {
                model: self.model,
                p: p.clone(),
                base: z0.clone(),
                free: self.free_states(),
                given: Vec::new(),
                signals: Vec::new(),
                columns: columns.clone(),
                zscale: self.zscale.clone(),
            };
            let x0 = sys.initial(&z0);
            let samples: Vec<f64> = (0..=b - a).map(|k| k as f64 * self.dt).collect();
            let traj = integrate(
                &sys,
                &x0,
                samples[samples.len() - 1],
                &samples,
                &self.sim,
                Hooks::default(),
            )
            .map_err(|source| FitError::Sim {
                stage: "multiple shooting".into(),
                source,
            })?;
            ends.push(traj.x[traj.x.len() - 1][..n].to_vec());
            // the last sample belongs to the next segment, except in the last one
            let used = if s + 1 == nseg { b - a + 1 } else { b - a };
            for (o, (_, st, data, sig, ov)) in self.outs.iter().enumerate() {
                let off = ov.map(|k| th[np + k]).unwrap_or(self.off0[o]);
                for k in 0..used {
                    let row = o * total + row0 + k;
                    let xr = &traj.x[k];
                    let y = xr[*st] + off;
                    yhat[o].push(y);
                    r[row] = (y - data[a + k]) / sig;
                    if sens {
                        for c in 0..n {
                            jm[(row, base + c)] = xr[n + c * n + st] / sig;
                        }
                        for c in 0..np {
                            jm[(row, c)] = xr[n + (n + c) * n + st] / sig;
                        }
                        if let Some(kv) = ov {
                            jm[(row, np + kv)] = self.vars[np + kv].scale / sig;
                        }
                    }
                }
            }
            row0 += used;
        }
        Ok(Eval {
            r,
            j: jm,
            yhat,
            ends,
        })
    }

    fn free_states(&self) -> Vec<usize> {
        (0..self.model.n_states()).collect()
    }
}

/// Refine the parameters `free` (indices) of `model` from `p0` and the offsets `off` by multiple
/// shooting over the training block `block` of `data`.
pub fn multiple_shooting(
    model: &dyn Model,
    p0: &[f64],
    free: &[usize],
    data: &Measured,
    off: &SensorOffsets,
    block: (f64, f64),
    opts: &MsOptions,
) -> Result<MultipleShooting, FitError> {
    let clock = Instant::now();
    let ch = channels(model, data)?;
    let (t0, dt) = (data.t[0], data.dt());
    let nt = data.t.len();
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(nt - 1);
    let a = idx(block.0);
    let b = idx(block.1.min(block.0 + opts.span));
    if b < a + 20 {
        return Err(FitError::ShortBlock {
            stage: "multiple shooting".into(),
            from: block.0,
            to: block.1,
            samples: b + 1 - a.min(b + 1),
            need: 21,
        });
    }
    let f = crate::signal::cycle_frequency(&ch[0].data[a..=b], dt)
        .or_else(|| crate::signal::cycle_frequency(&ch[1].data[a..=b], dt))
        .ok_or_else(|| FitError::BlockCycles {
            stage: "multiple shooting".into(),
            from: block.0,
            to: block.1,
        })?;
    let seg_len = ((opts.cycles / f / dt).round() as usize).max(10);
    let nseg = ((b - a) as f64 / seg_len as f64).round().max(1.0) as usize;
    let segs: Vec<(usize, usize)> = (0..nseg)
        .map(|s| (a + s * (b - a) / nseg, a + (s + 1) * (b - a) / nseg))
        .collect();
    let h = ((opts.smooth / dt).round() as usize).max(3);
    let n = model.n_states();
    let names = model.state_names();
    let sscale = state_scale(model, p0);
    let mut vars: Vec<Var> = free
        .iter()
        .map(|&j| Var {
            name: model.params()[j].name.into(),
            initial: p0[j],
            scale: p0[j].abs().max(1e-12),
        })
        .collect();
    let mut outs = Vec::new();
    let mut off0 = Vec::new();
    let mut n_off = 0;
    for c in &ch {
        let o = off.get(&c.name);
        let is_p = c.name.starts_with('p');
        let sig = noise_sigma(&c.data).max(if is_p { 1e-6 * sscale[c.state] } else { 1e-9 });
        let ov = if opts.offsets {
            vars.push(Var {
                name: format!("{}_offset", c.name),
                initial: o,
                scale: if is_p { 100.0 } else { 1e-3 },
            });
            n_off += 1;
            Some(n_off - 1)
        } else {
            None
        };
        outs.push((c.name.clone(), c.state, c.data.clone(), sig, ov));
        off0.push(o);
    }
    let states = model.states();
    for (s, &(sa, _)) in segs.iter().enumerate() {
        let x0 = measured_state(model, p0, data, off, sa, h)?;
        for i in 0..n {
            let scale = match states[i].kind {
                StateKind::Position(_) => 1e-3,
                StateKind::Velocity(_) => 0.05,
                StateKind::Pressure(_) | StateKind::Mass(_) | StateKind::WallTemperature(_) => {
                    0.01 * sscale[i]
                }
            };
            vars.push(Var {
                name: format!("seg{s}.{}", names[i]),
                initial: x0[i],
                scale,
            });
        }
    }
    let prob = Problem {
        model,
        p: p0.to_vec(),
        free: free.to_vec(),
        outs,
        off0,
        segs: segs.clone(),
        vars,
        n_off,
        dt,
        zscale: sscale.clone(),
        sim: opts.sim,
    };
    let mut last_err = None;
    let mut eval = |u: &[f64]| match prob.eval(u, true) {
        Ok(e) => Some((e.r, e.j)),
        Err(e) => {
            last_err = Some(e);
            None
        }
    };
    let u0 = vec![0.0; prob.vars.len()];
    let res = lm::minimize(&mut eval, &u0, &opts.lm).ok_or_else(|| {
        last_err
            .clone()
            .unwrap_or(FitError::Start("multiple shooting".into()))
    })?;
    let np = free.len();
    let vnames: Vec<(String, bool)> = prob
        .vars
        .iter()
        .enumerate()
        .map(|(k, v)| (v.name.clone(), k < np))
        .collect();
    let init: Vec<f64> = prob.vars.iter().map(|v| v.initial).collect();
    let scale: Vec<f64> = prob.vars.iter().map(|v| v.scale).collect();
    let stats = report::stats_full(
        &vnames,
        &init,
        &scale,
        &res.x,
        &res.residuals,
        &res.jacobian,
        0,
        None,
    );
    let fin = prob.eval(&res.x, false)?;
    let th = prob.values(&res.x);
    let mut p = p0.to_vec();
    for (k, &j) in free.iter().enumerate() {
        p[j] = th[k];
    }
    let mut offsets = off.clone();
    for (o, out) in prob.outs.iter().enumerate() {
        let v = out.4.map(|k| th[np + k]).unwrap_or(prob.off0[o]);
        match out.0.as_str() {
            "x" => offsets.x = v,
            "y" => offsets.y = v,
            "p" => offsets.p = v,
            "p_hot" => offsets.p_hot = Some(v),
            _ => {}
        }
    }
    let segments = segs
        .iter()
        .enumerate()
        .map(|(s, &(sa, sb))| {
            let defect = if s == 0 {
                0.0
            } else {
                let base = np + n_off + s * n;
                (0..n)
                    .map(|i| ((fin.ends[s - 1][i] - th[base + i]) / sscale[i]).abs())
                    .fold(0.0, f64::max)
            };
            Segment {
                t0: data.t[sa],
                t1: data.t[sb],
                defect,
            }
        })
        .collect();
    let fits = prob
        .outs
        .iter()
        .zip(&fin.yhat)
        .map(|((name, _, d, _, _), yh)| {
            let y = &d[a..a + yh.len()];
            let fp = fit_percent(y, yh);
            let rms = (y
                .iter()
                .zip(yh)
                .map(|(u, v)| (u - v) * (u - v))
                .sum::<f64>()
                / y.len() as f64)
                .sqrt();
            ChannelFit {
                channel: name.clone(),
                block: "segments".into(),
                fit_percent: fp,
                fit_percent_raw: fp,
                rms,
                samples: y.len(),
            }
        })
        .collect();
    Ok(MultipleShooting {
        stats,
        params: crate::params::named(model, &p),
        offsets,
        segments,
        fits,
        iterations: res.iterations,
        evaluations: res.evaluations,
        converged: res.converged,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
