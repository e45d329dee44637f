//! Measured data: a CSV with a header, `t` \[s\] and any of `p` (cold-side absolute pressure, Pa),
//! `p_hot` (Pa), `x`, `y` (m); `#` comment lines. A column may name its unit after its name
//! (`t [ms]`, `p [kPa gauge]`, `x [mm]`, `dV [cm^3]`, `theta [deg]`: [`units`](crate::data::units)); it is then
//! converted to SI as it is read. Other columns are kept by name when every row
//! holds a number there ([`crate::data::Measured::others`]: a channel a model declares with `sensor
//! name: STATE;`), and set aside with the first bad cell otherwise
//! ([`crate::data::Measured::unread`]), so that a fit asking for one can say where it failed.
//!
//! Every malformed input is a [`DataError`](crate::data::DataError) naming the file, the row
//! (1-based line number in the file) and the column. Sensor offsets are estimated
//! ([`offsets`](crate::data::offsets)), never assumed zero.

mod csv;
/// Sensor offsets, estimated from the data.
pub mod offsets;
/// Isolated outlier samples: found, refused by the fit, or replaced on request.
pub mod outliers;
mod sampling;
/// Reading a record line by line, under a memory limit.
pub mod stream;
mod text;
/// Units named in the header (`p [kPa gauge]`, `x [mm]`), converted to SI on reading.
pub mod units;

pub use csv::{
    parse_csv, parse_csv_bytes, read_csv, read_csv_lines, read_csv_within, write_csv, write_csv_to,
};
pub use offsets::{cycle_mean, remove_position_offsets, PositionOffsets};
pub use sampling::{check_uniform, UNIFORM_TOLERANCE};
pub use stream::ReadLimits;

use std::fmt;

/// The measured channels.
pub const CHANNELS: [&str; 4] = ["p", "p_hot", "x", "y"];

/// A malformed input: where and why.
#[derive(Clone, Debug, PartialEq)]
pub struct DataError {
    /// File name (or the source label given to [`parse_csv`]).
    pub file: String,
    /// 1-based line number in the file.
    pub row: usize,
    /// Column name (as in the header, or the expected name when it is missing).
    pub column: String,
    /// What is wrong and what was expected.
    pub message: String,
}

impl fmt::Display for DataError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}: row {}, column `{}`: {}",
            self.file, self.row, self.column, self.message
        )
    }
}

impl std::error::Error for DataError {}

/// A measured record: uniform or not, strictly increasing time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Measured {
    /// Where it came from (file name).
    pub source: String,
    pub t: Vec<f64>,
    pub p: Option<Vec<f64>>,
    pub p_hot: Option<Vec<f64>>,
    pub x: Option<Vec<f64>>,
    pub y: Option<Vec<f64>>,
    /// Columns besides `t` and the seed's four, in header order.
    pub others: Vec<(String, Vec<f64>)>,
    /// Columns besides the seed's four that could not be read: the first bad cell of each.
    pub unread: Vec<DataError>,
}

impl Measured {
    /// A channel by name (`p`, `p_hot`, `x`, `y`, or one of [`Measured::others`]).
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        match name {
            "p" => self.p.as_deref(),
            "p_hot" => self.p_hot.as_deref(),
            "x" => self.x.as_deref(),
            "y" => self.y.as_deref(),
            _ => self
                .others
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v.as_slice()),
        }
    }

    /// Why a column the record has could not be read (`None`: it is read, or absent).
    pub fn unread(&self, name: &str) -> Option<&DataError> {
        self.unread.iter().find(|e| e.column == name)
    }

    /// Mutable channel by name.
    pub fn channel_mut(&mut self, name: &str) -> Option<&mut Vec<f64>> {
        match name {
            "p" => self.p.as_mut(),
            "p_hot" => self.p_hot.as_mut(),
            "x" => self.x.as_mut(),
            "y" => self.y.as_mut(),
            _ => self
                .others
                .iter_mut()
                .find(|(n, _)| n == name)
                .map(|(_, v)| v),
        }
    }

    /// Names of the channels present: the seed's in the order p, p_hot, x, y, then the others.
    pub fn channels(&self) -> Vec<&str> {
        CHANNELS
            .into_iter()
            .filter(|c| self.channel(c).is_some())
            .chain(self.others.iter().map(|(n, _)| n.as_str()))
            .collect()
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Indices `[i0, i1)` of the samples with `a <= t <= b`.
    pub fn range(&self, a: f64, b: f64) -> (usize, usize) {
        let i0 = self.t.partition_point(|&t| t < a);
        let i1 = self.t.partition_point(|&t| t <= b);
        (i0, i1.max(i0))
    }

    /// The samples with `a <= t <= b` (time kept absolute).
    pub fn slice(&self, a: f64, b: f64) -> Measured {
        let (i0, i1) = self.range(a, b);
        let cut = |c: &Option<Vec<f64>>| c.as_ref().map(|v| v[i0..i1].to_vec());
        Measured {
            source: self.source.clone(),
            t: self.t[i0..i1].to_vec(),
            p: cut(&self.p),
            p_hot: cut(&self.p_hot),
            x: cut(&self.x),
            y: cut(&self.y),
            others: self
                .others
                .iter()
                .map(|(n, v)| (n.clone(), v[i0..i1].to_vec()))
                .collect(),
            unread: self.unread.clone(),
        }
    }

    /// Mean sample interval.
    pub fn dt(&self) -> f64 {
        if self.t.len() < 2 {
            return f64::NAN;
        }
        (self.t[self.t.len() - 1] - self.t[0]) / (self.t.len() - 1) as f64
    }
}

/// A malformed `a:b` time span.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpanError {
    #[error("expected a:b in seconds, e.g. 0:0.6")]
    Syntax,
    #[error("`{0}` is not a finite number of seconds")]
    Time(String),
    #[error("the block is empty: its end must be after its start")]
    Empty,
    #[error("the block reaches outside the record, which runs from {t0} s to {t1} s")]
    Outside { t0: f64, t1: f64 },
}

/// `a:b` as two times inside the record (either may be empty: start or end of the record);
/// one sample interval of slack is allowed at each end.
pub fn parse_span(s: &str, rec: &Measured) -> Result<(f64, f64), SpanError> {
    let (a, b) = s.split_once(':').ok_or(SpanError::Syntax)?;
    let t0 = rec.t.first().copied().unwrap_or(0.0);
    let t1 = rec.t.last().copied().unwrap_or(0.0);
    let num = |x: &str, d: f64| -> Result<f64, SpanError> {
        if x.trim().is_empty() {
            Ok(d)
        } else {
            x.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| SpanError::Time(x.trim().to_string()))
        }
    };
    let (a, b) = (num(a, t0)?, num(b, t1)?);
    if !(b > a) {
        return Err(SpanError::Empty);
    }
    let slack = if rec.t.len() > 1 { rec.dt() } else { 0.0 } + 1e-12 * t1.abs().max(t0.abs());
    if a < t0 - slack || b > t1 + slack {
        return Err(SpanError::Outside { t0, t1 });
    }
    Ok((a, b))
}
