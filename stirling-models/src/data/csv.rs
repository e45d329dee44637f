//! CSV reading with row- and column-precise errors, and writing.

use std::io::Write;
use std::path::Path;

use super::stream::{Estimate, Lines, ReadLimits};
use super::text::{fixed4, format_hint, names as list, quote, short};
use super::units::{self, Unit};
use super::{DataError, Measured, CHANNELS};

/// Read a measured record from a file (every row, under the default memory limit).
pub fn read_csv(path: &Path) -> Result<Measured, DataError> {
    read_csv_lines(path).map(|(m, _)| m)
}

/// Read a measured record and the file line of each sample (for messages about samples).
pub fn read_csv_lines(path: &Path) -> Result<(Measured, Vec<usize>), DataError> {
    read_csv_within(path, &ReadLimits::default())
}

/// Read the rows of a record that `lim` keeps, and the file line of each: the file is read
/// line by line, the other rows are checked and dropped, and a record whose kept rows would
/// pass the memory limit is refused after its first rows.
pub fn read_csv_within(path: &Path, lim: &ReadLimits) -> Result<(Measured, Vec<usize>), DataError> {
    let file = path.display().to_string();
    let cannot = |e: std::io::Error| DataError {
        file: file.clone(),
        row: 0,
        column: String::new(),
        message: format!("cannot read the file: {e}"),
    };
    let f = std::fs::File::open(path).map_err(cannot)?;
    let size = f.metadata().map_err(cannot)?.len();
    let mut lines = Lines::new(&file, std::io::BufReader::new(f));
    parse(&file, &mut lines, Some(size), lim)
}

/// Parse a measured record from bytes (UTF-8, an optional byte-order mark); `file` labels
/// the errors.
pub fn parse_csv_bytes(file: &str, bytes: &[u8]) -> Result<Measured, DataError> {
    let mut lines = Lines::new(file, bytes);
    parse(file, &mut lines, None, &ReadLimits::default()).map(|(m, _)| m)
}

/// Parse a measured record; `file` labels the errors.
pub fn parse_csv(file: &str, text: &str) -> Result<Measured, DataError> {
    parse_csv_bytes(file, text.as_bytes())
}

/// A record's header: its row, the column names and each column's unit, if given.
struct Header {
    row: usize,
    names: Vec<String>,
    units: Vec<Option<Unit>>,
}

impl Header {
    /// Column `i`'s value `v` in SI units.
    fn si(&self, i: usize, v: f64) -> f64 {
        self.units[i].as_ref().map_or(v, |u| u.si(v))
    }
}

/// Builds the errors of one file.
struct Errors<'a> {
    file: &'a str,
}

impl Errors<'_> {
    fn err(&self, row: usize, column: &str, message: String) -> DataError {
        DataError {
            file: self.file.to_string(),
            row,
            column: column.to_string(),
            message,
        }
    }

    /// The header line's row, column names and units (no column `t` or channel twice; a
    /// unit after a name, `p [kPa]`, must be one [`units::parse`] reads and fit the column).
    fn header(&self, first: Option<(usize, String)>) -> Result<Header, DataError> {
        let Some((hrow, header)) = first else {
            return Err(self.err(
                1,
                "t",
                "the file is empty: expected a header line with `t` and at least one of p, p_hot, x, y"
                    .into(),
            ));
        };
        let mut names = Vec::new();
        let mut units = Vec::new();
        for cell in header.split(',').map(|s| s.trim().trim_matches('"')) {
            let (name, unit) = units::split(cell);
            let unit = unit
                .map(|u| units::for_column(name, u))
                .transpose()
                .map_err(|m| self.err(hrow, cell, format!("the header's unit: {m}")))?;
            names.push(name.to_string());
            units.push(unit);
        }
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) && (n == "t" || CHANNELS.contains(&n.as_str())) {
                return Err(self.err(hrow, n, format!("column `{n}` appears twice in the header")));
            }
        }
        Ok(Header {
            row: hrow,
            names,
            units,
        })
    }

    /// The position of column `t` and of each measured channel present (the seed's four,
    /// then the others by name, each once).
    fn columns<'n>(
        &self,
        hrow: usize,
        names: &'n [String],
        body: &str,
    ) -> Result<(usize, Vec<(usize, &'n str)>), DataError> {
        let file = self.file;
        let Some(it) = names.iter().position(|n| n == "t") else {
            return Err(self.err(
                hrow,
                "t",
                format!(
                    "missing column `t` (time in s); the header has: {}{}",
                    list(names),
                    format_hint(file, body)
                ),
            ));
        };
        let mut cols: Vec<(usize, &str)> = CHANNELS
            .iter()
            .filter_map(|c| names.iter().position(|n| n == c).map(|i| (i, *c)))
            .collect();
        let seed = cols.len();
        for (i, n) in names.iter().enumerate() {
            let known = n == "t" || CHANNELS.contains(&n.as_str()) || n.is_empty();
            if !known && !names[..i].contains(n) {
                cols.push((i, n.as_str()));
            }
        }
        if seed == 0 && cols.is_empty() {
            return Err(self.err(hrow, "p", format!("no measured channel: expected at least one of the columns p, p_hot, x, y (or a sensor a model declares); the header has: {}{}", list(names), format_hint(file, body))));
        }
        Ok((it, cols))
    }

    /// Time `tv` on `row` must come strictly after the previous sample's `prev`.
    fn check_time(&self, row: usize, tv: f64, prev: Option<f64>) -> Result<(), DataError> {
        if let Some(prev) = prev {
            if tv == prev {
                return Err(self.err(
                    row,
                    "t",
                    format!(
                        "duplicate time {} (same as the previous row): time must increase strictly",
                        short(tv)
                    ),
                ));
            }
            if tv < prev {
                return Err(self.err(
                    row,
                    "t",
                    format!(
                        "time goes backwards ({} after {}): time must increase strictly",
                        short(tv),
                        short(prev)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The value of column `i` (named `name`) in a row's `fields`.
    fn field(
        &self,
        row: usize,
        fields: &[&str],
        n_names: usize,
        (i, name): (usize, &str),
    ) -> Result<f64, DataError> {
        let Some(s) = fields.get(i) else {
            return Err(self.err(
                row,
                name,
                format!(
                    "the row has {} fields, the header {}: value of `{name}` missing",
                    fields.len(),
                    n_names
                ),
            ));
        };
        number(s).map_err(|m| self.err(row, name, m))
    }

    /// The record from the columns read: each of the seed's channels checked for its units;
    /// another column kept when every row held a number (`bad[k]`: its first bad cell).
    fn record(
        &self,
        t: Vec<f64>,
        cols: &[(usize, &str)],
        mut data: Vec<Vec<f64>>,
        bad: Vec<Option<DataError>>,
        rows: &[usize],
    ) -> Result<Measured, DataError> {
        let mut m = Measured {
            source: self.file.to_string(),
            t,
            ..Default::default()
        };
        for (k, ((_, name), bad)) in cols.iter().zip(bad).enumerate() {
            let v = std::mem::take(&mut data[k]);
            if !CHANNELS.contains(name) {
                match bad {
                    Some(e) => m.unread.push(e),
                    None => m.others.push((name.to_string(), v)),
                }
                continue;
            }
            check_units(name, &v).map_err(|(at, msg)| match at {
                Some(i) => self.err(rows[i], name, msg),
                None => self.err(
                    rows[0],
                    name,
                    format!("{msg} (rows {}-{})", rows[0], rows[rows.len() - 1]),
                ),
            })?;
            *match *name {
                "p" => &mut m.p,
                "p_hot" => &mut m.p_hot,
                "x" => &mut m.x,
                _ => &mut m.y,
            } = Some(v);
        }
        Ok(m)
    }
}

/// The next line that is neither blank nor a comment, trimmed.
fn next<R: std::io::BufRead>(source: &mut Lines<R>) -> Result<Option<(usize, String)>, DataError> {
    for r in source.by_ref() {
        let (i, l) = r?;
        let l = l.trim();
        if !l.is_empty() && !l.starts_with('#') {
            return Ok(Some((i, l.to_string())));
        }
    }
    Ok(None)
}

/// The rows of a record: comment and blank lines skipped, each row's time checked against
/// the previous row's, the rows inside `lim.keep` stored.
fn parse<R: std::io::BufRead>(
    file: &str,
    source: &mut Lines<R>,
    size: Option<u64>,
    lim: &ReadLimits,
) -> Result<(Measured, Vec<usize>), DataError> {
    let e = Errors { file };
    let first_line = next(source)?;
    let raw = first_line
        .as_ref()
        .map(|(_, l)| l.clone())
        .unwrap_or_default();
    let head = e.header(first_line)?;
    let (hrow, names) = (head.row, &head.names);
    let (it, cols) = e.columns(hrow, names, &raw)?;
    let estimate = Estimate {
        size,
        columns: cols.len(),
    };
    let mut t = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); cols.len()];
    let mut bad: Vec<Option<DataError>> = vec![None; cols.len()];
    let mut rows = Vec::new();
    let (mut read, mut first, mut prev) = (0usize, None, None);
    let mut last_row = hrow;
    while let Some((row, line)) = next(source)? {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let tv = head.si(it, e.field(row, &fields, names.len(), (it, "t"))?);
        e.check_time(row, tv, prev)?;
        prev = Some(tv);
        let t0 = *first.get_or_insert(tv);
        read += 1;
        last_row = row;
        if Estimate::due(read) {
            estimate
                .check(lim, read, source.bytes, (t0, tv))
                .map_err(|m| e.err(row, "t", m))?;
        }
        if lim.keep.is_some_and(|(a, b)| tv < a || tv > b) {
            continue;
        }
        t.push(tv);
        for (k, &col) in cols.iter().enumerate() {
            match e.field(row, &fields, names.len(), col) {
                Ok(v) => data[k].push(head.si(col.0, v)),
                // another column: set aside at its first bad cell, the record still reads
                Err(err) if !CHANNELS.contains(&col.1) => {
                    bad[k].get_or_insert(err);
                }
                Err(err) => return Err(err),
            }
        }
        rows.push(row);
    }
    if read == 0 {
        return Err(e.err(hrow + 1, "t", "no data rows after the header".into()));
    }
    if let (Some((a, b)), true) = (lim.keep, t.len() < 2) {
        return Err(e.err(
            last_row,
            "t",
            format!(
                "only {} samples with t in {}:{} s, where the record runs from {} s to {} s: \
                 the blocks must lie inside the record",
                t.len(),
                short(a),
                short(b),
                short(first.unwrap_or(0.0)),
                short(prev.unwrap_or(0.0))
            ),
        ));
    }
    if t.len() < 2 {
        return Err(e.err(
            rows[0],
            "t",
            "only one data row: a record needs at least two samples".into(),
        ));
    }
    let m = e.record(t, &cols, data, bad, &rows)?;
    if m.channels().is_empty() {
        return Err(m.unread[0].clone());
    }
    Ok((m, rows))
}

/// A finite number, or why not.
fn number(s: &str) -> Result<f64, String> {
    if s.is_empty() {
        return Err("empty value: expected a number".into());
    }
    let v: f64 = s
        .parse()
        .map_err(|_| format!("not a number: {}", quote(s)))?;
    if v.is_finite() {
        Ok(v)
    } else if s.to_ascii_lowercase().contains("n") {
        Err(format!(
            "NaN or infinite value {}: expected a finite number",
            quote(s)
        ))
    } else {
        Err(format!(
            "{} is out of the range of a 64-bit number (about 1.8e308): expected a finite number",
            quote(s)
        ))
    }
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// The largest absolute pressure taken as a measurement (Pa): 10 kbar.
const P_MAX: f64 = 1e9;
/// The largest position magnitude (m).
const X_MAX: f64 = 0.5;

/// Units off by orders of magnitude (judged on the median: the whole column, `None`), then
/// single values out of range (`Some(index)`). Absolute pressure in Pa lies in 5e3..5e7 (an
/// engine charged between a twentieth of an atmosphere and 500 bar); positions in m within
/// 0.5 m.
fn check_units(name: &str, v: &[f64]) -> Result<(), (Option<usize>, String)> {
    let first = |bad: &dyn Fn(f64) -> bool| v.iter().position(|&x| bad(x));
    match name {
        "p" | "p_hot" => {
            let m = median(v);
            let whole = if m <= 0.0 {
                Some(format!("pressure must be absolute (Pa, > 0); median is {}: gauge pressure? name it in the header, e.g. `{name} [kPa gauge]` (the standard atmosphere is added), or add the ambient pressure", fixed4(m)))
            } else if m < 5.0e1 {
                Some(format!("pressure looks like bar or MPa (median {}): expected absolute pressure in Pa, e.g. 101325, or the unit named in the header, e.g. `{name} [bar]`", fixed4(m)))
            } else if m < 5.0e3 {
                Some(format!("pressure looks like kPa (median {}): expected absolute pressure in Pa, e.g. 101325, or the unit named in the header, e.g. `{name} [kPa]`", fixed4(m)))
            } else if m > 5.0e7 {
                Some(format!("pressure too large for Pa (median {:.4e}): expected absolute pressure in Pa, e.g. 101325", m))
            } else {
                None
            };
            if let Some(msg) = whole {
                return Err((None, msg));
            }
            if let Some(i) = first(&|x| x <= 0.0) {
                return Err((
                    Some(i),
                    format!(
                        "pressure {} Pa: pressure must be absolute (> 0)",
                        short(v[i])
                    ),
                ));
            }
            if let Some(i) = first(&|x| x > P_MAX) {
                return Err((Some(i), format!("pressure {} Pa is out of range (at most {P_MAX:.0e} Pa; the median is {}): a corrupt value?", short(v[i]), fixed4(m))));
            }
            Ok(())
        }
        _ => {
            let mags: Vec<f64> = v.iter().map(|x| x.abs()).collect();
            if median(&mags) > X_MAX {
                let peak = mags.iter().fold(0.0f64, |a, &b| a.max(b));
                return Err((None, format!("position looks like mm (largest magnitude {}): expected metres, e.g. 0.005 for 5 mm, or the unit named in the header, e.g. `{name} [mm]`", fixed4(peak))));
            }
            if let Some(i) = first(&|x| x.abs() > X_MAX) {
                return Err((Some(i), format!("position {} m is out of range (|{name}| <= {X_MAX} m; the median magnitude is {}): a corrupt value?", short(v[i]), fixed4(median(&mags)))));
            }
            Ok(())
        }
    }
}

/// Write a record (channels present in `m`, in the order t, p, p_hot, x, y, then the others),
/// with `#` comments.
/// The file is written whole or not at all ([`crate::output`]); an existing one is replaced.
pub fn write_csv(path: &Path, m: &Measured, comments: &[String]) -> std::io::Result<()> {
    let mut f = crate::output::Staged::new(path, true).map_err(std::io::Error::other)?;
    write_csv_to(&mut f, m, comments)?;
    f.commit(true).map_err(std::io::Error::other)
}

/// Write a record (as [`write_csv`]) to any writer.
pub fn write_csv_to(f: &mut impl Write, m: &Measured, comments: &[String]) -> std::io::Result<()> {
    for c in comments {
        writeln!(f, "# {c}")?;
    }
    let chans = m.channels();
    writeln!(f, "t,{}", chans.join(","))?;
    for (i, t) in m.t.iter().enumerate() {
        write!(f, "{t:.9e}")?;
        for c in &chans {
            write!(f, ",{:.9e}", m.channel(c).expect("present")[i])?;
        }
        writeln!(f)?;
    }
    f.flush()
}
