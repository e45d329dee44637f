//! The error of a figure that could not be drawn.

use std::path::Path;

/// A plot that could not be drawn.
#[derive(Debug, thiserror::Error)]
#[error("cannot draw {path}: {why}")]
pub struct DrawError {
    pub path: String,
    pub why: String,
}

impl DrawError {
    pub(crate) fn at(path: &Path) -> impl Fn(String) -> DrawError + '_ {
        move |why| DrawError {
            path: path.display().to_string(),
            why,
        }
    }
}

impl DrawError {
    /// The error of drawing `path` from any displayable backend error.
    pub(crate) fn on(path: &Path, why: &dyn std::fmt::Display) -> DrawError {
        DrawError {
            path: path.display().to_string(),
            why: why.to_string(),
        }
    }
}
