//! **How far**: the fraction of the held-out gap closed by an effect,
//! `1 - (err_after - 1) / (err_before - 1)`, where `err` is the held-out mean squared residual
//! in units of the noise variance (1 is the noise floor, so the fraction is taken on the excess
//! over the floor), with a percentile bootstrap interval that resamples whole cycles of the
//! held-out block (residuals are correlated within a cycle, roughly independent across).

use rand::{rngs::StdRng, Rng, SeedableRng};
use serde::Serialize;

use super::context::{Context, Eval};
use crate::data::Measured;
use crate::signal::cycle_starts;

/// The closure fraction with its interval.
#[derive(Clone, Debug, Serialize)]
pub struct Closure {
    pub fraction: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub err_before: f64,
    pub err_after: f64,
    pub cycles: usize,
}

/// Per-sample channel-averaged normalized squared residual.
fn sample_err(ev: &Eval, prof: &Context, i: usize) -> f64 {
    ev.channels
        .iter()
        .zip(&ev.hp)
        .map(|(c, r)| (r[i] / prof.noise_of(c)).powi(2))
        .sum::<f64>()
        / ev.channels.len() as f64
}

/// The closure fraction of `after` against `before` on the held-out range.
pub fn closure(
    data: &Measured,
    before: &Eval,
    after: &Eval,
    range: (usize, usize),
    prof: &Context,
    resamples: usize,
    seed: u64,
) -> Closure {
    let mut starts = cycle_starts(data, range);
    if starts.len() < 3 {
        // too few cycles: fixed blocks of a tenth of the range
        let len = ((range.1 - range.0) / 10).max(1);
        starts = (range.0..range.1).step_by(len).collect();
    }
    let mut cycles: Vec<(f64, f64, f64)> = Vec::new();
    for w in starts.windows(2) {
        let (mut a, mut b) = (0.0, 0.0);
        for i in w[0]..w[1] {
            a += sample_err(before, prof, i);
            b += sample_err(after, prof, i);
        }
        cycles.push((a, b, (w[1] - w[0]) as f64));
    }
    let frac = |cs: &mut dyn Iterator<Item = &(f64, f64, f64)>| {
        let (mut a, mut b, mut n) = (0.0, 0.0, 0.0);
        for c in cs {
            a += c.0;
            b += c.1;
            n += c.2;
        }
        let (eb, ea) = (a / n, b / n);
        (1.0 - (ea - 1.0) / (eb - 1.0), eb, ea)
    };
    let (fraction, err_before, err_after) = frac(&mut cycles.iter());
    let mut rng = StdRng::seed_from_u64(seed);
    let mut boots: Vec<f64> = (0..resamples)
        .map(|_| {
            let pick: Vec<&(f64, f64, f64)> = (0..cycles.len())
                .map(|_| &cycles[rng.gen_range(0..cycles.len())])
                .collect();
            frac(&mut pick.into_iter()).0
        })
        .filter(|v| v.is_finite())
        .collect();
    boots.sort_by(f64::total_cmp);
    let q = |p: f64| {
        if boots.is_empty() {
            f64::NAN
        } else {
            boots[((boots.len() - 1) as f64 * p).round() as usize]
        }
    };
    Closure {
        fraction,
        ci_low: q(0.025),
        ci_high: q(0.975),
        err_before,
        err_after,
        cycles: cycles.len(),
    }
}
