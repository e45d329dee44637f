//! Errors of model construction.

/// A model cannot be built as asked.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ModelError {
    /// `n` out of range.
    #[error("model `{model}`: n = {n} is not allowed ({why})")]
    Sections {
        model: &'static str,
        n: usize,
        why: &'static str,
    },
}
