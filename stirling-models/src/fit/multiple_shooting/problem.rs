//! The multiple-shooting least-squares problem: the variables, one evaluation (residuals and
//! Jacobian from forward sensitivities of every segment) and the result's assembly.

use nalgebra::DMatrix;
use stirling_dsl::Model;

use super::super::free_run::SensorOffsets;
use super::super::report::{self, ChannelFit, FitStats};
use super::super::sensitivity::{Column, Driven};
use super::super::{lm, FitError};
use super::setup::Out;
use super::Segment;
use crate::sim::{integrate, Hooks, SimOptions};

pub(super) struct Var {
    pub(super) name: String,
    pub(super) initial: f64,
    pub(super) scale: f64,
}

pub(super) struct Problem<'a> {
    pub(super) model: &'a dyn Model,
    pub(super) p: Vec<f64>,
    pub(super) free: Vec<usize>,
    /// The bounds of each free parameter.
    pub(super) bounds: Vec<Option<(f64, f64)>>,
    pub(super) outs: Vec<Out>,
    pub(super) off0: Vec<f64>,
    /// Sample ranges `[a, b]` (b is the next segment's a).
    pub(super) segs: Vec<(usize, usize)>,
    pub(super) vars: Vec<Var>,
    pub(super) n_off: usize,
    pub(super) dt: f64,
    pub(super) zscale: Vec<f64>,
    pub(super) sim: SimOptions,
}

pub(super) struct Eval {
    pub(super) r: Vec<f64>,
    pub(super) j: DMatrix<f64>,
    pub(super) yhat: Vec<Vec<f64>>,
    pub(super) ends: Vec<Vec<f64>>,
}

/// Where one segment's rows go: segment `s` covers samples `a..a + used`, from row `row0`.
struct SegRows {
    s: usize,
    a: usize,
    used: usize,
    row0: usize,
}

impl Problem<'_> {
    pub(super) fn values(&self, u: &[f64]) -> Vec<f64> {
        self.vars
            .iter()
            .zip(u)
            .map(|(v, u)| v.initial + v.scale * u)
            .collect()
    }

    /// All model parameters with the free ones taken from `th`.
    pub(super) fn params_with(&self, th: &[f64]) -> Vec<f64> {
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

    pub(super) fn eval(&self, u: &[f64], sens: bool) -> Result<Eval, FitError> {
        let th = self.values(u);
        let n = self.model.n_states();
        for (k, &b) in self.bounds.iter().enumerate() {
            super::super::vars::check_within(&self.vars[k].name, th[k], b)?;
        }
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
        let p = self.params_with(th);
        let mut dp = vec![0.0; p.len()];
        for (o, out) in self.outs.iter().enumerate() {
            let (reads, sig) = (out.obs.reads(), out.sigma);
            let mut dv = vec![0.0; reads.len()];
            let off = out.offset.map(|k| th[np + k]).unwrap_or(self.off0[o]);
            for k in 0..at.used {
                let row = o * total + at.row0 + k;
                let xr = &x[k];
                dp.iter_mut().for_each(|d| *d = 0.0);
                let y = out.obs.gradient(self.model, &p, xr, &mut dv, &mut dp) + off;
                ev.yhat[o].push(y);
                ev.r[row] = (y - out.data[at.a + k]) / sig;
                if !sens {
                    continue;
                }
                // d y / d column = sum over the reads of d y / d x_i times x_i's sensitivity
                let through = |col: usize| -> f64 {
                    reads
                        .iter()
                        .zip(&dv)
                        .map(|(&i, d)| d * xr[n + col * n + i])
                        .sum()
                };
                for c in 0..n {
                    ev.j[(row, base + c)] = through(c) / sig;
                }
                for (c, &j) in self.free.iter().enumerate() {
                    let direct = dp[j] * self.vars[c].scale;
                    ev.j[(row, c)] = (through(n + c) + direct) / sig;
                }
                if let Some(kv) = out.offset {
                    ev.j[(row, np + kv)] = self.vars[np + kv].scale / sig;
                }
            }
        }
    }

    fn free_states(&self) -> Vec<usize> {
        (0..self.model.n_states()).collect()
    }

    /// The sensor offsets at `th`: fitted ones from `th`, the others as given.
    pub(super) fn offsets_at(&self, th: &[f64], given: &SensorOffsets) -> SensorOffsets {
        let np = self.free.len();
        let mut offsets = given.clone();
        for (o, out) in self.outs.iter().enumerate() {
            let v = out.offset.map(|k| th[np + k]).unwrap_or(self.off0[o]);
            match out.name.as_str() {
                "x" => offsets.x = v,
                "y" => offsets.y = v,
                "p" => offsets.p = v,
                "p_hot" => offsets.p_hot = Some(v),
                other => match offsets.others.iter_mut().find(|(n, _)| n == other) {
                    Some(slot) => slot.1 = v,
                    None => offsets.others.push((other.to_string(), v)),
                },
            }
        }
        offsets
    }

    /// Each segment with its defect: the largest scaled jump from the previous segment's end.
    pub(super) fn segments(&self, fin: &Eval, th: &[f64], t: &[f64]) -> Vec<Segment> {
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
    pub(super) fn fits(&self, fin: &Eval, a: usize) -> Vec<ChannelFit> {
        self.outs
            .iter()
            .zip(&fin.yhat)
            .map(|(out, yh)| {
                ChannelFit::plain(&out.name, "segments", &out.data[a..a + yh.len()], yh)
            })
            .collect()
    }

    /// Statistics of the estimates at the optimum.
    pub(super) fn stats(&self, res: &lm::LmResult) -> FitStats {
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
    pub(super) fn solve(&self, opts: &lm::LmOptions) -> Result<lm::LmResult, FitError> {
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
