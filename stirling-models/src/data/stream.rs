//! A record file read line by line, never whole, and the memory limit of what is kept: the
//! rows of the blocks asked for are stored, the others are read and checked only, and a record
//! whose kept rows would pass the limit is refused up front (from the file's size and its first
//! rows) with the estimate, the limit and what to do.

use std::io::BufRead;

use super::text::format_hint;
use super::DataError;

/// The environment variable that sets the memory limit of a record, in MB.
pub const LIMIT_VAR: &str = "STIRLING_MAX_RECORD_MB";
/// The default memory limit of a record's kept rows (MB).
pub const DEFAULT_LIMIT_MB: f64 = 4096.0;
/// Data rows read before the estimate is made.
const SAMPLE_ROWS: usize = 1000;

/// Which rows of a record to keep and how much memory they may take.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReadLimits {
    /// Keep only the samples with `a <= t <= b` (the others are read and checked).
    pub keep: Option<(f64, f64)>,
    /// The memory the kept rows may take (bytes).
    pub max_bytes: f64,
    /// Bytes per kept row beyond the record's own numbers (what the analysis will need).
    pub work_per_row: f64,
}

impl Default for ReadLimits {
    /// Every row, under the limit of [`LIMIT_VAR`] (or [`DEFAULT_LIMIT_MB`]).
    fn default() -> Self {
        ReadLimits {
            keep: None,
            max_bytes: limit_mb() * 1e6,
            work_per_row: 0.0,
        }
    }
}

/// The limit of [`LIMIT_VAR`] in MB, or the default when unset or not a positive number.
pub fn limit_mb() -> f64 {
    std::env::var(LIMIT_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(DEFAULT_LIMIT_MB)
}

/// The lines of a reader as `(line number, text)`, each checked for UTF-8 (the error names
/// the byte offset and the line), a byte-order mark dropped, CR-only line ends refused.
pub struct Lines<R> {
    reader: R,
    file: String,
    line: usize,
    /// Bytes read so far.
    pub bytes: u64,
    buf: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    /// Lines of `reader`, errors labelled `file`.
    pub fn new(file: &str, reader: R) -> Self {
        Lines {
            reader,
            file: file.into(),
            line: 0,
            bytes: 0,
            buf: Vec::new(),
        }
    }

    fn err(&self, message: String) -> DataError {
        DataError {
            file: self.file.clone(),
            row: self.line,
            column: String::new(),
            message,
        }
    }
}

impl<R: BufRead> Iterator for Lines<R> {
    type Item = Result<(usize, String), DataError>;

    fn next(&mut self) -> Option<Self::Item> {
        self.buf.clear();
        let n = match self.reader.read_until(b'\n', &mut self.buf) {
            Ok(0) => return None,
            Ok(n) => n,
            Err(e) => return Some(Err(self.err(format!("cannot read the file: {e}")))),
        };
        self.line += 1;
        let start = self.bytes;
        self.bytes += n as u64;
        let text = match std::str::from_utf8(&self.buf) {
            Ok(t) => t,
            Err(e) => {
                let at = start + e.valid_up_to() as u64;
                let hint = format_hint(&self.file, "");
                return Some(Err(
                    self.err(format!("not a text file: invalid UTF-8 at byte {at}{hint}"))
                ));
            }
        };
        let text = if self.line == 1 {
            text.strip_prefix('\u{feff}').unwrap_or(text)
        } else {
            text
        };
        let text = text.strip_suffix('\n').unwrap_or(text);
        let text = text.strip_suffix('\r').unwrap_or(text);
        if text.contains('\r') {
            return Some(Err(self.err(
                "carriage returns (CR) inside the line: the file has old Mac line endings; \
                 convert them to LF or CRLF (e.g. `tr '\\r' '\\n' < in.csv > out.csv`)"
                    .into(),
            )));
        }
        if let Some(c) = text.chars().find(|c| c.is_control() && *c != '\t') {
            let hint = format_hint(&self.file, "");
            return Some(Err(self.err(format!(
                "not a text file: control character {:#04x} in the line{hint}",
                c as u32
            ))));
        }
        Some(Ok((self.line, text.to_string())))
    }
}

/// The memory estimate of a record, made after its first rows: refused when the rows it will
/// keep would take more than the limit.
pub struct Estimate {
    /// The file's size in bytes (`None`: unknown, e.g. text given in memory).
    pub size: Option<u64>,
    /// Numbers stored per kept row.
    pub columns: usize,
}

impl Estimate {
    /// Whether to judge now: after the first 1000 data rows (a shorter record is small).
    pub fn due(rows: usize) -> bool {
        rows == SAMPLE_ROWS
    }

    /// `rows` data rows read in `bytes` bytes, the first at `t0` and the last at `t`;
    /// `Err(message)` when the kept rows would pass the limit.
    pub fn check(
        &self,
        lim: &ReadLimits,
        rows: usize,
        bytes: u64,
        (t0, t): (f64, f64),
    ) -> Result<(), String> {
        let Some(size) = self.size.filter(|_| rows > 1 && bytes > 0) else {
            return Ok(());
        };
        let total = size as f64 * rows as f64 / bytes as f64;
        let dt = (t - t0) / (rows - 1) as f64;
        let kept = match lim.keep {
            Some((a, b)) if dt > 0.0 => total.min((b - a) / dt + 1.0),
            _ => total,
        };
        let per_row = 8.0 * (self.columns + 2) as f64 + lim.work_per_row;
        let need = kept * per_row;
        if need <= lim.max_bytes {
            return Ok(());
        }
        let what = if lim.keep.is_some() {
            "the blocks asked for hold"
        } else {
            "the record holds"
        };
        Err(format!(
            "{what} about {:.3e} rows (from the file's {:.0} MB and its first {rows} rows), \
             about {:.0} MB in memory at {per_row:.0} bytes a row, more than the limit of \
             {:.0} MB: give --train and --holdout to read only the blocks you need, cut the \
             file, or raise the limit with {LIMIT_VAR}=MB",
            kept,
            size as f64 / 1e6,
            need / 1e6,
            lim.max_bytes / 1e6
        ))
    }
}
