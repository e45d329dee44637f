//! CSV reading with row- and column-precise errors, and writing.

use std::io::Write;
use std::path::Path;

use super::{DataError, Measured, CHANNELS};

/// Read a measured record from a file.
pub fn read_csv(path: &Path) -> Result<Measured, DataError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| DataError {
        file: file.clone(),
        row: 0,
        column: String::new(),
        message: format!("cannot read the file: {e}"),
    })?;
    parse_csv(&file, &text)
}

/// Parse a measured record; `file` labels the errors.
pub fn parse_csv(file: &str, text: &str) -> Result<Measured, DataError> {
    let err = |row: usize, column: &str, message: String| DataError {
        file: file.to_string(),
        row,
        column: column.to_string(),
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    let Some((hrow, header)) = lines.next() else {
        return Err(err(
            1,
            "t",
            "the file is empty: expected a header line with `t` and at least one of p, p_hot, x, y"
                .into(),
        ));
    };
    let names: Vec<String> = header
        .split(',')
        .map(|s| s.trim().trim_matches('"').to_string())
        .collect();
    for (i, n) in names.iter().enumerate() {
        if names[..i].contains(n) && (n == "t" || CHANNELS.contains(&n.as_str())) {
            return Err(err(
                hrow,
                n,
                format!("column `{n}` appears twice in the header"),
            ));
        }
    }
    let Some(it) = names.iter().position(|n| n == "t") else {
        return Err(err(
            hrow,
            "t",
            format!(
                "missing column `t` (time in s); the header has: {}",
                names.join(", ")
            ),
        ));
    };
    let cols: Vec<(usize, &str)> = CHANNELS
        .iter()
        .filter_map(|c| names.iter().position(|n| n == c).map(|i| (i, *c)))
        .collect();
    if cols.is_empty() {
        return Err(err(hrow, "p", format!("no measured channel: expected at least one of the columns p, p_hot, x, y; the header has: {}", names.join(", "))));
    }
    let mut t = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); cols.len()];
    let mut rows = Vec::new();
    for (row, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let get = |i: usize, name: &str| -> Result<f64, DataError> {
            let Some(s) = fields.get(i) else {
                return Err(err(
                    row,
                    name,
                    format!(
                        "the row has {} fields, the header {}: value of `{name}` missing",
                        fields.len(),
                        names.len()
                    ),
                ));
            };
            if s.is_empty() {
                return Err(err(row, name, "empty value: expected a number".into()));
            }
            let v: f64 = s
                .parse()
                .map_err(|_| err(row, name, format!("not a number: `{s}`")))?;
            if !v.is_finite() {
                return Err(err(
                    row,
                    name,
                    format!("NaN or infinite value `{s}`: expected a finite number"),
                ));
            }
            Ok(v)
        };
        let tv = get(it, "t")?;
        if let Some(&prev) = t.last() {
            if tv == prev {
                return Err(err(row, "t", format!("duplicate time {tv} (same as the previous row): time must increase strictly")));
            }
            if tv < prev {
                return Err(err(
                    row,
                    "t",
                    format!("time goes backwards ({tv} after {prev}): time must increase strictly"),
                ));
            }
        }
        t.push(tv);
        for (k, (i, name)) in cols.iter().enumerate() {
            data[k].push(get(*i, name)?);
        }
        rows.push(row);
    }
    if t.is_empty() {
        return Err(err(hrow + 1, "t", "no data rows after the header".into()));
    }
    if t.len() < 2 {
        return Err(err(
            rows[0],
            "t",
            "only one data row: a record needs at least two samples".into(),
        ));
    }
    let mut m = Measured {
        source: file.to_string(),
        t,
        ..Default::default()
    };
    for (k, (_, name)) in cols.iter().enumerate() {
        let v = std::mem::take(&mut data[k]);
        check_units(name, &v).map_err(|msg| {
            err(
                rows[0],
                name,
                format!("{msg} (rows {}-{})", rows[0], rows[rows.len() - 1]),
            )
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

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[s.len() / 2]
}

/// Units off by orders of magnitude: absolute pressure in Pa lies in 5e3..5e7 (an engine
/// charged between a twentieth of an atmosphere and 500 bar); positions in m within 0.5 m.
fn check_units(name: &str, v: &[f64]) -> Result<(), String> {
    match name {
        "p" | "p_hot" => {
            let m = median(v);
            if m <= 0.0 {
                Err(format!("pressure must be absolute (Pa, > 0); median is {m:.4}: gauge pressure? add the ambient pressure"))
            } else if m < 5.0e1 {
                Err(format!("pressure looks like bar or MPa (median {m:.4}): expected absolute pressure in Pa, e.g. 101325"))
            } else if m < 5.0e3 {
                Err(format!("pressure looks like kPa (median {m:.4}): expected absolute pressure in Pa, e.g. 101325"))
            } else if m > 5.0e7 {
                Err(format!("pressure too large for Pa (median {m:.4e}): expected absolute pressure in Pa, e.g. 101325"))
            } else {
                Ok(())
            }
        }
        _ => {
            let peak = v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            if peak > 0.5 {
                Err(format!("position looks like mm (largest magnitude {peak:.4}): expected metres, e.g. 0.005 for 5 mm"))
            } else {
                Ok(())
            }
        }
    }
}

/// Write a record (channels present in `m`, in the order t, p, p_hot, x, y), with `#` comments.
pub fn write_csv(path: &Path, m: &Measured, comments: &[String]) -> std::io::Result<()> {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
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
