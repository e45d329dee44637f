//! The staggered integration of a [`Driven`](crate::fit::sensitivity::Driven) system: its free
//! states as an [`OdeSystem`](crate::sim::OdeSystem) of their own and its sensitivity columns as a
//! [`SensSystem`](crate::sim::SensSystem), so that diffsol's sensitivity BDF corrects every column
//! with the states' own Newton factorization ([`crate::sim::sens`]) instead of integrating the
//! augmented system `[z, S]`.

use std::cell::RefCell;

use stirling_dsl::JacSink;

use super::sensitivity::{Column, Driven};
use crate::sim::{integrate, integrate_sens, Hooks, OdeSystem, SensSystem, SimError, SimOptions};

impl Driven<'_> {
    /// Integrate from the free states `z0` to `t_end`; one row per sample: `[z, vec(S)]`
    /// (`z` alone without columns). The columns go through the staggered corrector
    /// ([`crate::sim::sens`]): the free states by BDF Newton, every column with the same
    /// `nz x nz` factorization.
    pub fn integrate(
        &self,
        z0: &[f64],
        t_end: f64,
        samples: &[f64],
        opts: &SimOptions,
    ) -> Result<Vec<Vec<f64>>, SimError> {
        let states = States {
            d: self,
            at: RefCell::new((f64::NAN, Vec::new())),
            scratch: RefCell::default(),
        };
        if self.columns.is_empty() {
            let traj = integrate(&states, z0, t_end, samples, opts, Hooks::default())?;
            return Ok(traj.x);
        }
        integrate_sens(&states, &states, z0, t_end, samples, opts)
    }
}

/// The free states of a [`Driven`] system alone, with their sensitivities as a
/// [`SensSystem`]. The prescribed states depend on `t` only: they are kept for the last `t`
/// (the Newton iterations of a step all evaluate at one time).
struct States<'d, 'a> {
    d: &'d Driven<'a>,
    at: RefCell<(f64, Vec<f64>)>,
    /// Buffers reused by every call (the calls run millions of times a fit; allocating them
    /// was 9 % of a diagnosis's profile).
    scratch: RefCell<Scratch>,
}

/// The work buffers of [`States`]: the full state, the model's right-hand side, its
/// Jacobian and its parameter Jacobian (dense, column-major).
#[derive(Default)]
struct Scratch {
    x: Vec<f64>,
    f: Vec<f64>,
    j: Vec<f64>,
    jp: Vec<f64>,
}

/// `buf` resized to `len` and zeroed.
fn zeroed(buf: &mut Vec<f64>, len: usize) -> &mut [f64] {
    buf.clear();
    buf.resize(len, 0.0);
    buf
}

impl States<'_, '_> {
    /// [`Driven::full_state`] into `x`, the prescribed part reused while `t` stays.
    fn full_state(&self, t: f64, z: &[f64], x: &mut Vec<f64>) {
        let mut at = self.at.borrow_mut();
        if at.0 != t {
            *at = (t, self.d.full_state(t, z));
        }
        x.clear();
        x.extend_from_slice(&at.1);
        for (k, &i) in self.d.free.iter().enumerate() {
            x[i] = z[k];
        }
    }

    /// The model's dense Jacobian at the full state `x` into `j`.
    fn jacobian(&self, t: f64, x: &[f64], j: &mut Vec<f64>) {
        let n = self.d.model.n_states();
        let data = zeroed(j, n * n);
        let mut sink = JacSink::Dense { data, nrows: n };
        self.d.model.jacobian(&self.d.p, x, t, &mut sink);
    }
}

impl OdeSystem for States<'_, '_> {
    fn dim(&self) -> usize {
        self.d.free.len()
    }

    fn rhs(&self, t: f64, z: &[f64], out: &mut [f64]) {
        let d = self.d;
        let mut s = self.scratch.borrow_mut();
        let Scratch { x, f, .. } = &mut *s;
        self.full_state(t, z, x);
        let f = zeroed(f, d.model.n_states());
        d.model.rhs(&d.p, x, t, f);
        for (k, &i) in d.free.iter().enumerate() {
            out[k] = f[i];
        }
    }

    /// `J_zz`, the free states' block of the model Jacobian.
    fn jac(&self, t: f64, z: &[f64], jac: &mut [f64]) {
        let d = self.d;
        let (nz, n) = (d.free.len(), d.model.n_states());
        let mut s = self.scratch.borrow_mut();
        let Scratch { x, j, .. } = &mut *s;
        self.full_state(t, z, x);
        self.jacobian(t, x, j);
        for (c, &ic) in d.free.iter().enumerate() {
            for (r, &ir) in d.free.iter().enumerate() {
                jac[r + c * nz] += j[ir + n * ic];
            }
        }
    }

    fn scale(&self) -> Vec<f64> {
        self.d.zscale.clone()
    }
}

impl SensSystem for States<'_, '_> {
    fn n_sens(&self) -> usize {
        self.d.columns.len()
    }

    /// Column `c`: `f_p[:, index] scale` (parameter), `0` (initial state), or
    /// `f_u du/dtheta` (prescribed inputs), restricted to the free rows.
    fn sens_forcing(&self, t: f64, z: &[f64], out: &mut [f64]) {
        let d = self.d;
        let (nz, n) = (d.free.len(), d.model.n_states());
        out.fill(0.0);
        let mut s = self.scratch.borrow_mut();
        let Scratch { x, j, jp, .. } = &mut *s;
        self.full_state(t, z, x);
        if d.columns.iter().any(|c| matches!(c, Column::Param { .. })) {
            let data = zeroed(jp, n * d.model.params().len());
            let mut sink = JacSink::Dense { data, nrows: n };
            d.model.param_jacobian(&d.p, x, t, &mut sink);
        }
        let need_u = d
            .columns
            .iter()
            .any(|c| matches!(c, Column::Input { .. } | Column::Signals { .. }));
        if need_u {
            self.jacobian(t, x, j);
        }
        for (k, c) in d.columns.iter().enumerate() {
            let o = &mut out[k * nz..(k + 1) * nz];
            match c {
                Column::Param { index, scale } => {
                    for (r, &ir) in d.free.iter().enumerate() {
                        o[r] = jp[ir + n * index] * scale;
                    }
                }
                Column::Initial { .. } => {}
                _ => {
                    let du = d.input_rates(c, t);
                    for (r, &ir) in d.free.iter().enumerate() {
                        o[r] = d
                            .given
                            .iter()
                            .zip(&du)
                            .map(|(g, r)| j[ir + n * g.state] * r)
                            .sum();
                    }
                }
            }
        }
    }

    fn sens_initial(&self, out: &mut [f64]) {
        let nz = self.d.free.len();
        out.fill(0.0);
        for (k, c) in self.d.columns.iter().enumerate() {
            if let Column::Initial { pos, scale } = c {
                out[k * nz + pos] = *scale;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::registry::build;
    use crate::sim::state_scale;
    use stirling_dsl::Closure;

    /// The staggered sensitivity columns of a free run of `nsection` n = 2 (a parameter and
    /// an initial state) against central differences of the plain integration.
    #[test]
    fn staggered_columns_match_finite_differences() {
        let model = build("nsection", Some(2), Closure::Full).unwrap();
        let mut p = model.default_params();
        let n = model.n_states();
        let mut z0 = vec![0.0; n];
        model.equilibrium_guess(&p, &mut z0);
        z0[0] += 2e-3;
        let kd = model.param_index("kd").unwrap();
        let driven = |p: &[f64], columns: Vec<Column>| Driven {
            model: model.as_ref(),
            p: p.to_vec(),
            base: z0.clone(),
            free: (0..n).collect(),
            given: Vec::new(),
            signals: Vec::new(),
            columns,
            zscale: state_scale(model.as_ref(), p),
        };
        let samples = [0.0, 0.01, 0.02];
        let opts = SimOptions {
            rtol: 1e-10,
            atol: 1e-10,
            ..SimOptions::default()
        };
        let cols = vec![
            Column::Param {
                index: kd,
                scale: 1.0,
            },
            Column::Initial {
                pos: 0,
                scale: 1e-4,
            },
        ];
        let rows = driven(&p, cols)
            .integrate(&z0, 0.02, &samples, &opts)
            .unwrap();
        let run = |p: &[f64], z: &[f64]| {
            driven(p, Vec::new())
                .integrate(z, 0.02, &samples, &opts)
                .unwrap()
        };
        let (h, hz) = (1e-3 * p[kd], 1e-7);
        p[kd] += h;
        let up = run(&p, &z0);
        p[kd] -= 2.0 * h;
        let dn = run(&p, &z0);
        p[kd] += h;
        let (mut zu, mut zd) = (z0.clone(), z0.clone());
        zu[0] += hz;
        zd[0] -= hz;
        let (iu, id) = (run(&p, &zu), run(&p, &zd));
        let scale = state_scale(model.as_ref(), &p);
        for k in 1..samples.len() {
            for i in 0..n {
                let fd_p = (up[k][i] - dn[k][i]) / (2.0 * h);
                let fd_z = (iu[k][i] - id[k][i]) / (2.0 * hz) * 1e-4;
                let (sp, sz) = (rows[k][n + i], rows[k][2 * n + i]);
                let tol = 1e-4 * scale[i];
                assert!(
                    (sp - fd_p).abs() < tol * 1e-2 + 1e-4 * fd_p.abs(),
                    "d/dkd state {i} sample {k}: {sp} vs {fd_p}"
                );
                assert!(
                    (sz - fd_z).abs() < tol + 1e-4 * fd_z.abs(),
                    "d/dz0 state {i} sample {k}: {sz} vs {fd_z}"
                );
            }
        }
    }
}
