//! **How far**: the fraction of the held-out gap closed by an effect,
//! `1 - (err_after - 1) / (err_before - 1)`, where `err` is the held-out mean squared residual
//! in units of the noise variance (1 is the noise floor, so the fraction is taken on the excess
//! over the floor), with a percentile bootstrap interval that resamples whole cycles of the
//! held-out block (residuals are correlated within a cycle, roughly independent across).

use serde::Serialize;

use super::context::{Context, Eval};
use crate::data::Measured;
use crate::signal::{cycle_starts, percentile_interval, resamples as resamples_of};

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
    let cycles = cycle_errors(data, before, after, range, prof);
    let (closed, err_before, err_after) = fraction(cycles.iter());
    let boots = resamples_of(cycles.len(), resamples, seed)
        .iter()
        .map(|pick| fraction(pick.iter().map(|&i| &cycles[i])).0)
        .collect();
    let (ci_low, ci_high) = percentile_interval(boots);
    Closure {
        fraction: closed,
        ci_low,
        ci_high,
        err_before,
        err_after,
        cycles: cycles.len(),
    }
}

/// Per cycle of the held-out range: the summed errors before and after, and the sample count.
fn cycle_errors(
    data: &Measured,
    before: &Eval,
    after: &Eval,
    range: (usize, usize),
    prof: &Context,
) -> Vec<(f64, f64, f64)> {
    let mut starts = cycle_starts(data, range);
    if starts.len() < 3 {
        // too few cycles: fixed blocks of a tenth of the range
        let len = ((range.1 - range.0) / 10).max(1);
        starts = (range.0..range.1).step_by(len).collect();
    }
    starts
        .windows(2)
        .map(|w| {
            let (mut a, mut b) = (0.0, 0.0);
            for i in w[0]..w[1] {
                a += sample_err(before, prof, i);
                b += sample_err(after, prof, i);
            }
            (a, b, (w[1] - w[0]) as f64)
        })
        .collect()
}

/// The closure fraction of a set of cycles, with the mean errors before and after.
fn fraction<'c>(cycles: impl Iterator<Item = &'c (f64, f64, f64)>) -> (f64, f64, f64) {
    let (mut a, mut b, mut n) = (0.0, 0.0, 0.0);
    for c in cycles {
        a += c.0;
        b += c.1;
        n += c.2;
    }
    let (eb, ea) = (a / n, b / n);
    (1.0 - (ea - 1.0) / (eb - 1.0), eb, ea)
}
