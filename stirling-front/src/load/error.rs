//! What a load reports: the diagnostics at their place in a file, rendered like rustc's.

use std::fmt;
use std::path::PathBuf;

/// One message at a place in a file (`line` 1-based, `column` 1-based in characters; both
/// 0 when the message has no place in the text, e.g. a file that cannot be read).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub path: String,
    pub line: usize,
    pub column: usize,
    pub message: String,
    /// The source line and the caret under the span (empty without a place).
    pub snippet: String,
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            return write!(f, "{}: {}", self.path, self.message);
        }
        write!(
            f,
            "{}:{}:{}: {}",
            self.path, self.line, self.column, self.message
        )?;
        if !self.snippet.is_empty() {
            write!(f, "\n{}", self.snippet)?;
        }
        Ok(())
    }
}

/// Why a file did not load.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file (or a file it extends) cannot be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The declaration is wrong: every message, at its place.
    #[error("{}", render(.0))]
    Invalid(Vec<Diagnostic>),
}

impl LoadError {
    /// The diagnostics (none for a file that cannot be read).
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            LoadError::Invalid(d) => d,
            LoadError::Read { .. } => &[],
        }
    }
}

fn render(all: &[Diagnostic]) -> String {
    let parts: Vec<String> = all.iter().map(Diagnostic::to_string).collect();
    parts.join("\n\n")
}
