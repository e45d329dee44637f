//! Cycles of a periodic signal: upward crossings of the mean, the cycle frequency, the cycle starts.

use crate::data::{cycle_mean, Measured};

/// An upward crossing of a signal's mean: `index` is the sample where the signal leaves the
/// hysteresis band (mean +- half the standard deviation) upwards, so noise cannot add
/// crossings; `at` is the mean crossing before it, interpolated between samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    pub index: usize,
    pub at: f64,
}

/// The upward crossings of the mean of `y` (the one detector the analyses share).
pub fn upward_crossings(y: &[f64]) -> Vec<Crossing> {
    let n = y.len().max(1) as f64;
    let m = y.iter().sum::<f64>() / n;
    let sd = (y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n).sqrt();
    let (lo, hi) = (m - 0.5 * sd, m + 0.5 * sd);
    let mut armed = false;
    let mut last_below = 0;
    let mut ups = Vec::new();
    for (i, &v) in y.iter().enumerate() {
        if v < m {
            last_below = i;
        }
        if v < lo {
            armed = true;
        } else if armed && v > hi {
            armed = false;
            let (a, b) = (y[last_below], y[last_below + 1]);
            ups.push(Crossing {
                index: i,
                at: last_below as f64 + (m - a) / (b - a),
            });
        }
    }
    ups
}

/// Cycle frequency (Hz) from the [`upward_crossings`], counted at whole samples (`None`:
/// fewer than 2 cycles).
pub fn cycle_frequency(y: &[f64], dt: f64) -> Option<f64> {
    let ups = upward_crossings(y);
    let (first, last) = (ups.first()?, ups.last()?);
    (ups.len() >= 3).then(|| (ups.len() - 1) as f64 / ((last.index - first.index) as f64 * dt))
}

/// Cycle frequency (Hz) from the interpolated [`upward_crossings`] (`None`: fewer than 2
/// cycles).
pub fn crossing_frequency(y: &[f64], dt: f64) -> Option<f64> {
    let ups = upward_crossings(y);
    let (first, last) = (ups.first()?, ups.last()?);
    (ups.len() >= 3).then(|| (ups.len() - 1) as f64 / ((last.at - first.at) * dt))
}

/// Sample indices of upward crossings of the displacer position through its mean in `range`.
pub fn cycle_starts(data: &Measured, range: (usize, usize)) -> Vec<usize> {
    let Some(x) = data.x.as_ref().or(data.p.as_ref()) else {
        return vec![range.0, range.1];
    };
    let m = cycle_mean(x);
    // smooth a little so noise does not make spurious crossings
    let h = 3usize;
    let sm: Vec<f64> = (0..x.len())
        .map(|i| {
            let a = i.saturating_sub(h);
            let b = (i + h + 1).min(x.len());
            x[a..b].iter().sum::<f64>() / (b - a) as f64 - m
        })
        .collect();
    let mut out = Vec::new();
    let mut last: Option<usize> = None;
    for i in range.0.max(1)..range.1 {
        if sm[i - 1] < 0.0 && sm[i] >= 0.0 && last.is_none_or(|l| i - l > 10) {
            out.push(i);
            last = Some(i);
        }
    }
    out
}
