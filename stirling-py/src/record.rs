//! Measured records: built from arrays (checked: equal lengths, finite values, strictly
//! increasing time) or read from a CSV with the library's row- and column-precise errors;
//! written as the rig writes them.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use stirling_models::data::{self, Measured};

use crate::arrays::{array1, vector};
use crate::errors::{self, Failure, Kind, Res};

/// A record and, when read from a file, the file line of each sample (for messages).
#[pyclass(module = "stirling._native", frozen)]
pub struct NativeRecord {
    pub data: Measured,
    pub lines: Option<Vec<usize>>,
}

impl NativeRecord {
    pub fn plain(data: Measured) -> Self {
        NativeRecord { data, lines: None }
    }

    /// Uniform sampling, as the fit and the diagnosis need it.
    pub fn check_uniform(&self) -> Res<()> {
        data::check_uniform(&self.data, self.lines.as_deref())
            .map(|_| ())
            .map_err(Failure::from)
    }
}

fn record_error(message: String) -> Failure {
    Failure::new(Kind::Record, message)
}

/// A channel name a CSV header can hold.
fn check_name(name: &str) -> Res<()> {
    let bad = name.is_empty()
        || name == "t"
        || name
            .chars()
            .any(|c| c == ',' || c == '#' || c.is_whitespace() || c.is_control());
    if bad {
        return Err(record_error(format!(
            "channel name `{name}`: a channel is named by a non-empty word without commas, `#` or spaces, other than `t`"
        )));
    }
    Ok(())
}

/// Strictly increasing times.
fn check_time(t: &[f64]) -> Res<()> {
    if t.len() < 2 {
        return Err(record_error(format!(
            "t has {} samples: a record needs at least two",
            t.len()
        )));
    }
    match t.windows(2).position(|w| !(w[1] > w[0])) {
        None => Ok(()),
        Some(k) => Err(record_error(format!(
            "t must increase strictly: t[{}] = {} is not after t[{k}] = {}",
            k + 1,
            t[k + 1],
            t[k]
        ))),
    }
}

fn as_record_error(e: PyErr, py: Python<'_>) -> PyErr {
    // a shape or value error of an array becomes the record's
    record_error(e.value(py).to_string()).into()
}

#[pymethods]
impl NativeRecord {
    /// A record from `t` (s) and channels by name (`p`, `p_hot` in Pa; `x`, `y` in m; any
    /// other name as a declared sensor's column).
    #[new]
    #[pyo3(signature = (t, channels, source="arrays".to_string()))]
    fn new(
        py: Python<'_>,
        t: &Bound<'_, PyAny>,
        channels: &Bound<'_, PyDict>,
        source: String,
    ) -> PyResult<Self> {
        let t = vector(t, "t", None).map_err(|e| as_record_error(e, py))?;
        check_time(&t)?;
        let mut m = Measured {
            source,
            t,
            ..Default::default()
        };
        if channels.is_empty() {
            return Err(record_error(
                "a record needs at least one channel besides t (p, x, y, ...)".into(),
            )
            .into());
        }
        for (k, v) in channels.iter() {
            let name: String = k.str()?.extract()?;
            check_name(&name)?;
            let what = format!("channel `{name}`");
            let n = m.t.len();
            let values = vector(&v, &what, Some((n, "one per sample of t")))
                .map_err(|e| as_record_error(e, py))?;
            if m.channel(&name).is_some() {
                return Err(record_error(format!("channel `{name}` is given twice")).into());
            }
            match name.as_str() {
                "p" => m.p = Some(values),
                "p_hot" => m.p_hot = Some(values),
                "x" => m.x = Some(values),
                "y" => m.y = Some(values),
                _ => m.others.push((name, values)),
            }
        }
        Ok(NativeRecord::plain(m))
    }

    #[getter]
    fn source(&self) -> &str {
        &self.data.source
    }

    #[getter]
    fn t<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        array1(py, self.data.t.clone()).into_any()
    }

    /// The channels present: p, p_hot, x, y in that order, then the others.
    fn channels(&self) -> Vec<String> {
        self.data.channels().into_iter().map(String::from).collect()
    }

    /// One channel's samples.
    fn channel<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        match self.data.channel(name) {
            Some(v) => Ok(array1(py, v.to_vec()).into_any()),
            None => Err(record_error(format!(
                "the record has no channel `{name}`; it has: {}",
                self.data.channels().join(", ")
            ))
            .into()),
        }
    }

    fn __len__(&self) -> usize {
        self.data.len()
    }

    /// The samples with `a <= t <= b` (s).
    fn slice(&self, a: f64, b: f64) -> Self {
        NativeRecord::plain(self.data.slice(a, b))
    }

    /// Write the record as CSV (the rig's format: 10 significant digits) with `#` comments;
    /// an existing file is refused unless `force`.
    #[pyo3(signature = (path, comments=Vec::new(), force=false))]
    fn write_csv(&self, path: PathBuf, comments: Vec<String>, force: bool) -> PyResult<()> {
        if path.exists() && !force {
            return Err(Failure::option(format!(
                "{} exists: pass force=True to overwrite it",
                path.display()
            ))
            .into());
        }
        data::write_csv(&path, &self.data, &comments).map_err(|e| errors::io(&path, &e))
    }
}

/// Read a measured record from a CSV file (`t` and any of `p`, `p_hot`, `x`, `y`, other
/// columns by name; `#` comments).
#[pyfunction]
pub fn read_csv(path: PathBuf) -> PyResult<NativeRecord> {
    let (data, lines) = data::read_csv_lines(&path).map_err(Failure::from)?;
    Ok(NativeRecord {
        data,
        lines: Some(lines),
    })
}
