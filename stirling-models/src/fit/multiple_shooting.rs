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

use super::free_run::{channels, measured_state, sample_range, Channel, SensorOffsets};
use super::report::{self, ChannelFit, FitStats};
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

/// Where one segment's rows go: segment `s` covers samples `a..a + used`, from row `row0`.
struct SegRows {
    s: usize,
    a: usize,
    used: usize,
    row0: usize,
}

impl Problem<'_> {
    fn values(&self, u: &[f64]) -> Vec<f64> {
        self.vars
            .iter()
            .zip(u)
            .map(|(v, u)| v.initial + v.scale * u)
            .collect()
    }

    /// All model parameters with the free ones taken from `th`.
    fn params_with(&self, th: &[f64]) -> Vec<f64> {
        let mut p = self.p.clone();
        for (k, &j) in self.free.iter().enumerate() {
            p[j] = th[k];
        }
        p
    }

    /// The sensitivity columns: every initial state, then the free parameters.
    fn columns(&self) -> Vec<Column> {
        let (np, no, n) = (self.free.len(), self.n_off, self.model.n_states());
        let mut columns: Vec<Column> = Vec::new();
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
        columns
    }

    fn eval(&self, u: &[f64], sens: bool) -> Result<Eval, FitError> {
        let th = self.values(u);
        let n = self.model.n_states();
        let p = self.params_with(&th);
        let columns = if sens { self.columns() } else { Vec::new() };
        let rows: usize = self.segs.iter().map(|(a, b)| b - a).sum::<usize>() + 1;
        let rows = rows * self.outs.len();
        let mut ev = Eval {
            r: vec![0.0; rows],
            j: DMatrix::zeros(if sens { rows } else { 0 }, self.vars.len()),
            yhat: vec![Vec::new(); self.outs.len()],
            ends: Vec::new(),
        };
        let nseg = self.segs.len();
        let mut row0 = 0;
        for (s, &(a, b)) in self.segs.iter().enumerate() {
            let x = self.simulate_segment(s, b - a, &th, &p, &columns)?;
            ev.ends.push(x[x.len() - 1][..n].to_vec());
            // the last sample belongs to the next segment, except in the last one
            let used = if s + 1 == nseg { b - a + 1 } else { b - a };
            let at = SegRows { s, a, used, row0 };
            self.fill_rows(&mut ev, &x, &at, &th, sens);
            row0 += used;
        }
        Ok(ev)
    }

    /// Integrate segment `s` (`len` sample steps) freely from its initial state in `th`.
    fn simulate_segment(
        &self,
        s: usize,
        len: usize,
        th: &[f64],
        p: &[f64],
        columns: &[Column],
    ) -> Result<Vec<Vec<f64>>, FitError> {
        let n = self.model.n_states();
        let base = self.free.len() + self.n_off + s * n;
        let z0 = th[base..base + n].to_vec();
        let sys = Driven {
            model: self.model,
            p: p.to_vec(),
            base: z0.clone(),
            free: self.free_states(),
            given: Vec::new(),
            signals: Vec::new(),
            columns: columns.to_vec(),
            zscale: self.zscale.clone(),
        };
        let x0 = sys.initial(&z0);
        let samples: Vec<f64> = (0..=len).map(|k| k as f64 * self.dt).collect();
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
        Ok(traj.x)
    }

    /// Write one segment's residuals, model outputs and (with `sens`) Jacobian rows.
    fn fill_rows(&self, ev: &mut Eval, x: &[Vec<f64>], at: &SegRows, th: &[f64], sens: bool) {
        let (np, no, n) = (self.free.len(), self.n_off, self.model.n_states());
        let base = np + no + at.s * n;
        let total = ev.r.len() / self.outs.len();
        for (o, (_, st, data, sig, ov)) in self.outs.iter().enumerate() {
            let off = ov.map(|k| th[np + k]).unwrap_or(self.off0[o]);
            for k in 0..at.used {
                let row = o * total + at.row0 + k;
                let xr = &x[k];
                let y = xr[*st] + off;
                ev.yhat[o].push(y);
                ev.r[row] = (y - data[at.a + k]) / sig;
                if sens {
                    for c in 0..n {
                        ev.j[(row, base + c)] = xr[n + c * n + st] / sig;
                    }
                    for c in 0..np {
                        ev.j[(row, c)] = xr[n + (n + c) * n + st] / sig;
                    }
                    if let Some(kv) = ov {
                        ev.j[(row, np + kv)] = self.vars[np + kv].scale / sig;
                    }
                }
            }
        }
    }

    fn free_states(&self) -> Vec<usize> {
        (0..self.model.n_states()).collect()
    }

    /// The sensor offsets at `th`: fitted ones from `th`, the others as given.
    fn offsets_at(&self, th: &[f64], given: &SensorOffsets) -> SensorOffsets {
        let np = self.free.len();
        let mut offsets = given.clone();
        for (o, out) in self.outs.iter().enumerate() {
            let v = out.4.map(|k| th[np + k]).unwrap_or(self.off0[o]);
            match out.0.as_str() {
                "x" => offsets.x = v,
                "y" => offsets.y = v,
                "p" => offsets.p = v,
                "p_hot" => offsets.p_hot = Some(v),
                _ => {}
            }
        }
        offsets
    }

    /// Each segment with its defect: the largest scaled jump from the previous segment's end.
    fn segments(&self, fin: &Eval, th: &[f64], t: &[f64]) -> Vec<Segment> {
        let (np, n) = (self.free.len(), self.model.n_states());
        self.segs
            .iter()
            .enumerate()
            .map(|(s, &(sa, sb))| {
                let defect = if s == 0 {
                    0.0
                } else {
                    let base = np + self.n_off + s * n;
                    (0..n)
                        .map(|i| ((fin.ends[s - 1][i] - th[base + i]) / self.zscale[i]).abs())
                        .fold(0.0, f64::max)
                };
                Segment {
                    t0: t[sa],
                    t1: t[sb],
                    defect,
                }
            })
            .collect()
    }

    /// Fit per channel over the segments, from the block's first sample `a`.
    fn fits(&self, fin: &Eval, a: usize) -> Vec<ChannelFit> {
        self.outs
            .iter()
            .zip(&fin.yhat)
            .map(|((name, _, d, _, _), yh)| {
                ChannelFit::plain(name, "segments", &d[a..a + yh.len()], yh)
            })
            .collect()
    }

    /// Statistics of the estimates at the optimum.
    fn stats(&self, res: &lm::LmResult) -> FitStats {
        let np = self.free.len();
        let vnames: Vec<(String, bool)> = self
            .vars
            .iter()
            .enumerate()
            .map(|(k, v)| (v.name.clone(), k < np))
            .collect();
        let init: Vec<f64> = self.vars.iter().map(|v| v.initial).collect();
        let scale: Vec<f64> = self.vars.iter().map(|v| v.scale).collect();
        report::stats_full(
            &vnames,
            &init,
            &scale,
            &res.x,
            &res.residuals,
            &res.jacobian,
            0,
            None,
        )
    }

    /// Minimise the output error over all variables (scaled, from 0).
    fn solve(&self, opts: &lm::LmOptions) -> Result<lm::LmResult, FitError> {
        let mut last_err = None;
        let mut eval = |u: &[f64]| match self.eval(u, true) {
            Ok(e) => Some((e.r, e.j)),
            Err(e) => {
                last_err = Some(e);
                None
            }
        };
        let u0 = vec![0.0; self.vars.len()];
        lm::minimize(&mut eval, &u0, opts).ok_or_else(|| {
            last_err
                .clone()
                .unwrap_or(FitError::Start("multiple shooting".into()))
        })
    }
}

/// Cut `[a, b]` into segments of about `opts.cycles` cycles of the measured frequency.
fn cut_segments(
    ch: &[Channel],
    (a, b): (usize, usize),
    dt: f64,
    block: (f64, f64),
    cycles: f64,
) -> Result<Vec<(usize, usize)>, FitError> {
    let f = crate::signal::cycle_frequency(&ch[0].data[a..=b], dt)
        .or_else(|| crate::signal::cycle_frequency(&ch[1].data[a..=b], dt))
        .ok_or_else(|| FitError::BlockCycles {
            stage: "multiple shooting".into(),
            from: block.0,
            to: block.1,
        })?;
    let seg_len = ((cycles / f / dt).round() as usize).max(10);
    let nseg = ((b - a) as f64 / seg_len as f64).round().max(1.0) as usize;
    Ok((0..nseg)
        .map(|s| (a + s * (b - a) / nseg, a + (s + 1) * (b - a) / nseg))
        .collect())
}

/// The free model parameters as variables, scaled by their starting values.
fn param_vars(model: &dyn Model, p0: &[f64], free: &[usize]) -> Vec<Var> {
    free.iter()
        .map(|&j| Var {
            name: model.params()[j].name.into(),
            initial: p0[j],
            scale: p0[j].abs().max(1e-12),
        })
        .collect()
}

/// What [`output_vars`] builds: the outputs, their given offsets, how many offsets are fitted.
struct Outputs {
    outs: Vec<(String, usize, Vec<f64>, f64, Option<usize>)>,
    off0: Vec<f64>,
    n_off: usize,
}

/// The measured outputs with their noise levels; with `fit_offsets`, one offset variable each.
fn output_vars(
    ch: &[Channel],
    off: &SensorOffsets,
    sscale: &[f64],
    fit_offsets: bool,
    vars: &mut Vec<Var>,
) -> Outputs {
    let mut outs = Vec::new();
    let mut off0 = Vec::new();
    let mut n_off = 0;
    for c in ch {
        let o = off.get(&c.name);
        let is_p = c.name.starts_with('p');
        let sig = noise_sigma(&c.data).max(if is_p { 1e-6 * sscale[c.state] } else { 1e-9 });
        let ov = if fit_offsets {
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
    Outputs { outs, off0, n_off }
}

/// Every segment's initial state as variables, started from the smoothed measurements.
fn segment_vars(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    off: &SensorOffsets,
    segs: &[(usize, usize)],
    (h, sscale): (usize, &[f64]),
    vars: &mut Vec<Var>,
) -> Result<(), FitError> {
    let n = model.n_states();
    let names = model.state_names();
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
    Ok(())
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
    let dt = data.dt();
    let end = block.1.min(block.0 + opts.span);
    let (a, b) = sample_range(data, block, end, "multiple shooting", 21)?;
    let segs = cut_segments(&ch, (a, b), dt, block, opts.cycles)?;
    let h = ((opts.smooth / dt).round() as usize).max(3);
    let sscale = state_scale(model, p0);
    let mut vars = param_vars(model, p0, free);
    let outputs = output_vars(&ch, off, &sscale, opts.offsets, &mut vars);
    segment_vars(model, p0, data, off, &segs, (h, &sscale), &mut vars)?;
    let prob = Problem {
        model,
        p: p0.to_vec(),
        free: free.to_vec(),
        outs: outputs.outs,
        off0: outputs.off0,
        segs,
        vars,
        n_off: outputs.n_off,
        dt,
        zscale: sscale,
        sim: opts.sim,
    };
    let res = prob.solve(&opts.lm)?;
    let stats = prob.stats(&res);
    let fin = prob.eval(&res.x, false)?;
    let th = prob.values(&res.x);
    Ok(MultipleShooting {
        stats,
        params: crate::params::named(model, &prob.params_with(&th)),
        offsets: prob.offsets_at(&th, off),
        segments: prob.segments(&fin, &th, &data.t),
        fits: prob.fits(&fin, a),
        iterations: res.iterations,
        evaluations: res.evaluations,
        converged: res.converged,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
