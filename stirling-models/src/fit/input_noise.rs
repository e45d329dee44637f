//! Errors in variables: how the noise on a stage's prescribed inputs moves its estimates, by
//! Monte Carlo over noise records smoothed like the signals.

use nalgebra::{DMatrix, DVector};

use super::driven::Stage;
use super::FitError;
use crate::signal::{project_drift, savitzky_golay};

impl Stage<'_> {
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
        if self.input_noise.is_empty() || draws == 0 {
            return Ok(Vec::new());
        }
        let base = self.run(u, first, last, false)?;
        // the noise records are drawn in turn (the same records as one draw after the
        // other), the runs are independent: in parallel
        let noisy: Vec<Stage> = self.noisy_stages(draws, seed);
        use rayon::prelude::*;
        noisy
            .par_iter()
            .map(|st| {
                let run = st.run(u, first, last, false)?;
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
                Ok(dr)
            })
            .collect()
    }

    /// `draws` copies of the stage with noise records (white, smoothed like the signal) added
    /// to its noisy inputs, drawn in turn from `seed`.
    fn noisy_stages(&self, draws: usize, seed: u64) -> Vec<Stage<'_>> {
        use rand::{rngs::StdRng, Rng, SeedableRng};
        let mut rng = StdRng::seed_from_u64(seed);
        let mut gauss = move || {
            let u1: f64 = 1.0 - rng.gen::<f64>();
            let u2: f64 = rng.gen::<f64>();
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        };
        (0..draws)
            .map(|_| {
                let mut noisy = Stage {
                    input_noise: Vec::new(),
                    ..self.clone()
                };
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
                noisy
            })
            .collect()
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
}
