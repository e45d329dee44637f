//! Isolated outliers in a record: samples that a smooth signal through their neighbours does
//! not come near. A single corrupt sample (a position of 0.4 m in a record of millimetres)
//! pulled a fit's heat transfer to twice its truth with no warning; a fit refuses a record
//! with outliers, naming them, and `--drop-outliers` replaces each by its neighbours'
//! interpolation.
//!
//! The test, per channel: each sample against the cubic through the two samples either side,
//! `(-y[k-2] + 4 y[k-1] + 4 y[k+1] - y[k+2]) / 6` (exact for a cubic; at 10 samples per cycle,
//! the least a fit accepts, it misses a sine by about 5 % of its amplitude, and by far less at
//! usual rates); the scale is the median absolute deviation of those differences over the
//! channel, so the sensor's noise and the interpolation's own error set it. A sample more
//! than [`OUTLIER_SIGMAS`](crate::data::outliers::OUTLIER_SIGMAS) scales off is an outlier: the largest first, replaced, and the test
//! repeated (one corrupt sample also moves its neighbours' interpolations).

use super::Measured;

/// Scales (robust standard deviations) beyond which a sample is an outlier: never reached by
/// Gaussian noise in any record (the chance is below 1e-30 per sample).
pub const OUTLIER_SIGMAS: f64 = 12.0;

/// Most outliers looked for per channel; more than this is not a few corrupt samples.
pub const MAX_OUTLIERS: usize = 20;

/// One outlier.
#[derive(Clone, Debug, PartialEq)]
pub struct Outlier {
    pub channel: String,
    pub index: usize,
    pub t: f64,
    pub value: f64,
    /// The neighbours' interpolation at the sample.
    pub expected: f64,
    /// How far off, in robust standard deviations.
    pub sigmas: f64,
}

impl std::fmt::Display for Outlier {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "`{}` at sample {} (t = {:.6} s, data row {}): {:.6e} where its neighbours give {:.6e} ({:.0} robust sd off)",
            self.channel,
            self.index,
            self.t,
            self.index + 1,
            self.value,
            self.expected,
            self.sigmas
        )
    }
}

fn interpolate(y: &[f64], k: usize) -> f64 {
    (-y[k - 2] + 4.0 * y[k - 1] + 4.0 * y[k + 1] - y[k + 2]) / 6.0
}

/// The robust scale of the interpolation differences of `y` (0 when there are too few).
fn scale(y: &[f64]) -> f64 {
    if y.len() < 9 {
        return 0.0;
    }
    let mut d: Vec<f64> = (2..y.len() - 2)
        .map(|k| (y[k] - interpolate(y, k)).abs())
        .collect();
    d.sort_by(f64::total_cmp);
    d[d.len() / 2] / 0.6745
}

/// The outliers of one channel, largest first, each replaced in `y` by its interpolation.
fn channel_outliers(name: &str, t: &[f64], y: &mut [f64]) -> Vec<Outlier> {
    let s = scale(y);
    let mut out = Vec::new();
    if !(s > 0.0) || !s.is_finite() {
        return out;
    }
    while out.len() < MAX_OUTLIERS {
        let worst = (2..y.len() - 2)
            .map(|k| (k, (y[k] - interpolate(y, k)).abs() / s))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, sig)) = worst.filter(|w| w.1 > OUTLIER_SIGMAS) else {
            break;
        };
        let expected = interpolate(y, k);
        out.push(Outlier {
            channel: name.to_string(),
            index: k,
            t: t[k],
            value: y[k],
            expected,
            sigmas: sig,
        });
        y[k] = expected;
    }
    out
}

/// Every channel's outliers (the record untouched; one channel copied at a time, not the
/// whole record).
pub fn find(m: &Measured) -> Vec<Outlier> {
    m.channels()
        .iter()
        .filter_map(|c| m.channel(c).map(|y| (c, y.to_vec())))
        .flat_map(|(c, mut y)| channel_outliers(c, &m.t, &mut y))
        .collect()
}

/// Replace every channel's outliers by their neighbours' interpolation; the outliers found.
pub fn repair(m: &mut Measured) -> Vec<Outlier> {
    let names: Vec<String> = m.channels().iter().map(|c| c.to_string()).collect();
    let t = m.t.clone();
    let mut out = Vec::new();
    for name in names {
        if let Some(y) = m.channel_mut(&name) {
            out.extend(channel_outliers(&name, &t, y));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(rate: f64, spike: Option<(usize, f64)>) -> Measured {
        let n = 4000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
        let mut seed = 7u64;
        let mut noise = || {
            // a small deterministic generator: sums of uniforms, about Gaussian
            (0..12)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                    (seed >> 11) as f64 / (1u64 << 53) as f64
                })
                .sum::<f64>()
                - 6.0
        };
        let mut x: Vec<f64> = t
            .iter()
            .map(|t| 0.01 * (std::f64::consts::TAU * 13.4 * t).sin() + 2e-5 * noise())
            .collect();
        if let Some((k, v)) = spike {
            x[k] = v;
        }
        Measured {
            source: "test".into(),
            t,
            x: Some(x),
            ..Default::default()
        }
    }

    #[test]
    fn a_clean_record_has_none_at_any_usual_rate() {
        for rate in [134.0, 500.0, 2000.0, 20000.0] {
            assert_eq!(find(&record(rate, None)), vec![], "{rate} Hz");
        }
    }

    #[test]
    fn one_corrupt_sample_is_found_and_repaired() {
        let mut m = record(2000.0, Some((1234, 0.4)));
        let found = repair(&mut m);
        assert_eq!(found.len(), 1, "{found:?}");
        assert_eq!(found[0].index, 1234);
        let truth = 0.01 * (std::f64::consts::TAU * 13.4 * m.t[1234]).sin();
        assert!((m.x.as_ref().unwrap()[1234] - truth).abs() < 1e-4);
        assert!(found[0].to_string().contains("data row 1235"));
    }
}
