//! Uniform sampling, as the fit and the diagnosis need it: the typical interval is the median
//! one, so a gap is reported where it is (not at the first ordinary interval, which differs
//! from a mean inflated by the gap).

use super::text::short;
use super::{DataError, Measured};

/// Relative deviation from the typical interval taken as irregular.
pub const UNIFORM_TOLERANCE: f64 = 1e-3;

/// The sample interval of a uniformly sampled record, else the first irregular interval.
/// `lines` (from [`super::read_csv_lines`]) are the file lines of the samples; without them
/// the error gives the data row (1-based sample number).
pub fn check_uniform(m: &Measured, lines: Option<&[usize]>) -> Result<f64, DataError> {
    let n = m.t.len();
    let row = |k: usize| lines.and_then(|l| l.get(k).copied()).unwrap_or(k + 1);
    let err = |k: usize, message: String| DataError {
        file: m.source.clone(),
        row: row(k),
        column: "t".into(),
        message,
    };
    if n < 2 {
        return Err(err(0, format!("{n} samples: a record needs at least two")));
    }
    let mut d: Vec<f64> = m.t.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    let dt = d[d.len() / 2];
    for k in 1..n {
        let step = m.t[k] - m.t[k - 1];
        if !((step - dt).abs() <= UNIFORM_TOLERANCE * dt) {
            let what = if step > dt { "a gap" } else { "a short step" };
            return Err(err(
                k,
                format!(
                    "irregular sampling: {what} of {} s from t = {} s (row {}) to t = {} s, where the typical interval is {} s; the fit needs uniform sampling (resample the record)",
                    short(step),
                    short(m.t[k - 1]),
                    row(k - 1),
                    short(m.t[k]),
                    short(dt)
                ),
            ));
        }
    }
    Ok(dt)
}
