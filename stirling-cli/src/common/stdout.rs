//! The checked stdout. A reader that stops early (`stirling models --json | head`) closes the pipe;
//! the next write then fails with [`StdoutClosed`](crate::common::stdout::StdoutClosed) inside an
//! `io::Error`, which `main` turns into a quiet exit instead of a panic. Notes on stderr never
//! fail.

use std::fmt;
use std::io::{self, Write};

use serde::Serialize;

/// The reader of stdout has gone (a broken pipe): the end of the output, not a failure.
#[derive(Debug)]
pub struct StdoutClosed;

impl fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("stdout was closed by its reader")
    }
}

impl std::error::Error for StdoutClosed {}

/// Stdout whose broken pipe becomes [`StdoutClosed`]; use with `writeln!(out, ...)?`.
pub struct Out(io::StdoutLock<'static>);

/// The checked stdout.
pub fn stdout() -> Out {
    Out(io::stdout().lock())
}

impl Write for Out {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf).map_err(mark)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.0.flush().map_err(mark)
    }
}

fn mark(e: io::Error) -> io::Error {
    if e.kind() == io::ErrorKind::BrokenPipe {
        io::Error::new(io::ErrorKind::BrokenPipe, StdoutClosed)
    } else {
        e
    }
}

/// Print `text` as it is (no newline added).
pub fn print(text: &str) -> io::Result<()> {
    let mut o = stdout();
    o.write_all(text.as_bytes())?;
    o.flush()
}

/// Print a value as pretty JSON and a newline.
pub fn print_json<T: Serialize + ?Sized>(value: &T) -> anyhow::Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    let mut o = stdout();
    writeln!(o, "{text}")?;
    o.flush()?;
    Ok(())
}

/// Whether `e` is (caused by) the closed stdout.
pub fn is_stdout_closed(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.is::<StdoutClosed>()
            || c.downcast_ref::<io::Error>()
                .and_then(|io| io.get_ref())
                .is_some_and(|inner| inner.is::<StdoutClosed>())
    })
}

/// A line on stderr (progress, what was written); a closed stderr is ignored.
pub fn note(msg: impl fmt::Display) {
    let _ = writeln!(io::stderr(), "{msg}");
}
