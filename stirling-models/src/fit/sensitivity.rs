//! Forward sensitivities of a driven subsystem: the free states `z` integrated with the other
//! states prescribed, `z' = f_z(z, u(t); p)`, and `S' = f_z S + F` where each column of `S` is
//! the derivative of `z` with respect to one fit variable:
//! - a model parameter: `F = f_p[:, j] * scale` (the generated parameter Jacobian);
//! - an initial free state: `F = 0`, `S(0) = scale * e_i`;
//! - a prescribed input that depends on the variable: `F = f_u du/dtheta * scale`.
//!
//! Both `f_z` and `f_u` are sub-blocks of the generated state Jacobian.

use stirling_dsl::{JacSink, Model};

use crate::sim::OdeSystem;

/// A prescribed signal: cubic Hermite through uniform samples of a value and its derivative.
#[derive(Clone, Debug)]
pub struct Signal {
    pub t0: f64,
    pub dt: f64,
    pub val: Vec<f64>,
    pub der: Vec<f64>,
}

impl Signal {
    /// Value and derivative at `t` (clamped to the record).
    pub fn eval(&self, t: f64) -> (f64, f64) {
        let n = self.val.len();
        let s = ((t - self.t0) / self.dt).clamp(0.0, (n - 1) as f64);
        let k = (s.floor() as usize).min(n - 2);
        let u = s - k as f64;
        let (y0, y1, d0, d1) = (
            self.val[k],
            self.val[k + 1],
            self.der[k] * self.dt,
            self.der[k + 1] * self.dt,
        );
        let (u2, u3) = (u * u, u * u * u);
        let v = (2.0 * u3 - 3.0 * u2 + 1.0) * y0
            + (u3 - 2.0 * u2 + u) * d0
            + (-2.0 * u3 + 3.0 * u2) * y1
            + (u3 - u2) * d1;
        let dv = ((6.0 * u2 - 6.0 * u) * y0
            + (3.0 * u2 - 4.0 * u + 1.0) * d0
            + (-6.0 * u2 + 6.0 * u) * y1
            + (3.0 * u2 - 2.0 * u) * d1)
            / self.dt;
        (v, dv)
    }
}

/// How a prescribed state is made: `sum w * (signal value or derivative) + constant + sum_k
/// dtheta[k] * theta_k` (the last part is carried by [`Column::Input`]).
#[derive(Clone, Debug)]
pub struct Given {
    pub state: usize,
    /// `(signal, weight, use the derivative)`.
    pub terms: Vec<(usize, f64, bool)>,
    pub constant: f64,
}

impl Given {
    /// State `state` read from one signal's value (or derivative) plus a constant.
    pub fn signal(state: usize, signal: usize, derivative: bool, constant: f64) -> Given {
        Given {
            state,
            terms: vec![(signal, 1.0, derivative)],
            constant,
        }
    }
}

/// One sensitivity column.
#[derive(Clone, Debug)]
pub enum Column {
    /// Model parameter `index`, in units of `scale`.
    Param { index: usize, scale: f64 },
    /// Initial value of free state number `pos` (position in the free list), in units of `scale`.
    Initial { pos: usize, scale: f64 },
    /// Prescribed inputs move by `du[g] * scale` per unit (one entry per [`Given`]).
    Input { du: Vec<f64>, scale: f64 },
    /// Prescribed input `g` moves by `signal_s(t) * scale` per unit, for each `(g, s)`.
    Signals {
        pairs: Vec<(usize, usize)>,
        scale: f64,
    },
}

/// A driven subsystem with its sensitivities, as an [`OdeSystem`]: state `[z, vec(S)]`.
#[derive(Clone)]
pub struct Driven<'a> {
    pub model: &'a dyn Model,
    pub p: Vec<f64>,
    /// The full state template (prescribed entries are overwritten, free ones ignored).
    pub base: Vec<f64>,
    pub free: Vec<usize>,
    pub given: Vec<Given>,
    pub signals: Vec<Signal>,
    pub columns: Vec<Column>,
    /// Typical magnitude of each free state.
    pub zscale: Vec<f64>,
}

impl Driven<'_> {
    /// The full model state at `t` with free states `z`.
    pub fn full_state(&self, t: f64, z: &[f64]) -> Vec<f64> {
        let mut x = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            x[i] = z[k];
        }
        for g in &self.given {
            let mut v = g.constant;
            for &(s, w, d) in &g.terms {
                let (a, b) = self.signals[s].eval(t);
                v += w * if d { b } else { a };
            }
            x[g.state] = v;
        }
        x
    }

    /// Initial augmented state `[z0, vec(S0)]`.
    pub fn initial(&self, z0: &[f64]) -> Vec<f64> {
        let nz = self.free.len();
        let mut out = z0.to_vec();
        out.resize(nz * (1 + self.columns.len()), 0.0);
        for (k, c) in self.columns.iter().enumerate() {
            if let Column::Initial { pos, scale } = c {
                out[nz + k * nz + pos] = *scale;
            }
        }
        out
    }
}

impl Driven<'_> {
    /// The rate of every prescribed state per unit of column `c` at `t` (empty when the
    /// column moves no prescribed state: parameters and initial states).
    pub(super) fn input_rates(&self, c: &Column, t: f64) -> Vec<f64> {
        match c {
            Column::Param { .. } | Column::Initial { .. } => Vec::new(),
            Column::Input { du, scale } => du.iter().map(|d| d * scale).collect(),
            Column::Signals { pairs, scale } => {
                let mut du = vec![0.0; self.given.len()];
                for &(g, s) in pairs {
                    du[g] += self.signals[s].eval(t).0 * scale;
                }
                du
            }
        }
    }

    /// Call `f(row, col, value)` for every entry of the augmented Jacobian: the free-state
    /// block of `df/dx` repeated along the diagonal.
    fn for_each_block_entry(&self, t: f64, xa: &[f64], mut f: impl FnMut(usize, usize, f64)) {
        let nz = self.free.len();
        let n = self.model.n_states();
        let x = self.full_state(t, &xa[..nz]);
        let mut j = vec![0.0; n * n];
        self.model.jacobian(
            &self.p,
            &x,
            t,
            &mut JacSink::Dense {
                data: &mut j,
                nrows: n,
            },
        );
        for b in 0..=self.columns.len() {
            let off = b * nz;
            for (c, &ic) in self.free.iter().enumerate() {
                for (r, &ir) in self.free.iter().enumerate() {
                    f(off + r, off + c, j[ir + n * ic]);
                }
            }
        }
    }
}

impl OdeSystem for Driven<'_> {
    fn dim(&self) -> usize {
        self.free.len() * (1 + self.columns.len())
    }

    fn rhs(&self, t: f64, xa: &[f64], out: &mut [f64]) {
        let nz = self.free.len();
        let n = self.model.n_states();
        let x = self.full_state(t, &xa[..nz]);
        let mut f = vec![0.0; n];
        self.model.rhs(&self.p, &x, t, &mut f);
        for (k, &i) in self.free.iter().enumerate() {
            out[k] = f[i];
        }
        if self.columns.is_empty() {
            return;
        }
        let j = self.model.jacobian_dense(&self.p, &x, t);
        let need_p = self
            .columns
            .iter()
            .any(|c| matches!(c, Column::Param { .. }));
        let jp = if need_p {
            self.model.param_jacobian_dense(&self.p, &x, t)
        } else {
            Vec::new()
        };
        for (k, c) in self.columns.iter().enumerate() {
            let s = &xa[nz + k * nz..nz + (k + 1) * nz];
            let o = &mut out[nz + k * nz..nz + (k + 1) * nz];
            // how each prescribed state moves per unit of this column (once per call)
            let du = self.input_rates(c, t);
            for (r, &ir) in self.free.iter().enumerate() {
                let mut acc = 0.0;
                for (cc, &ic) in self.free.iter().enumerate() {
                    acc += j[ir + n * ic] * s[cc];
                }
                acc += match c {
                    Column::Param { index, scale } => jp[ir + n * index] * scale,
                    _ => self
                        .given
                        .iter()
                        .zip(&du)
                        .map(|(g, d)| j[ir + n * g.state] * d)
                        .sum::<f64>(),
                };
                o[r] = acc;
            }
        }
    }

    fn jac(&self, t: f64, xa: &[f64], jac: &mut [f64]) {
        let d = self.dim();
        self.for_each_block_entry(t, xa, |r, c, v| jac[r + c * d] += v);
    }

    /// Block diagonal: the free states' Jacobian block once per sensitivity column (the
    /// staggered structure), dense within a block. The sparse LU then factors the blocks
    /// separately, `(1 + columns) nz^3` instead of `((1 + columns) nz)^3`.
    fn sparsity(&self) -> Option<Vec<(usize, usize)>> {
        let nz = self.free.len();
        Some(
            (0..=self.columns.len())
                .flat_map(|b| {
                    (0..nz).flat_map(move |c| (0..nz).map(move |r| (b * nz + r, b * nz + c)))
                })
                .collect(),
        )
    }

    fn jac_triplets(&self, t: f64, xa: &[f64], out: &mut Vec<(usize, usize, f64)>) {
        self.for_each_block_entry(t, xa, |r, c, v| out.push((r, c, v)));
    }

    fn scale(&self) -> Vec<f64> {
        let mut s = self.zscale.clone();
        for _ in &self.columns {
            s.extend_from_slice(&self.zscale);
        }
        s
    }
}
