//! How a [`Tape`] runs: by the interpreter loop ([`Tape::run`], on every target), or by
//! native code a JIT compiled from it (a [`Runner`], e.g. the `stirling-jit` crate's),
//! installed on a model with [`CompiledModel::with_jit`](super::CompiledModel::with_jit).

use std::fmt::Debug;
use std::sync::Arc;

use super::tape::Tape;

/// A tape compiled to something faster than the interpreter: writes output `k` of the tape
/// it was compiled from to `head[k]` (`tail[k - s]` from the tape's [`Tape::split`] `s`
/// on), exactly as [`Tape::run`] computes it.
pub trait Runner: Debug + Send + Sync {
    /// Run on the state `x`, the parameters `p` and the sensor reads `v`.
    /// `false` (nothing written) when a slice is too short for the tape: the caller runs the
    /// interpreter then.
    fn run(&self, x: &[f64], p: &[f64], v: &[f64], head: &mut [f64], tail: &mut [f64]) -> bool;

    /// Whether the code loops over the tape's repeating sections ([`Tape::repeat`]).
    fn looped(&self) -> bool {
        false
    }

    /// The size of the native code in bytes, if known.
    fn code_bytes(&self) -> Option<usize> {
        None
    }
}

/// A JIT: the runner of a tape, or `None` where it cannot compile it (the interpreter runs
/// that tape then).
pub type Jit = fn(&Tape) -> Option<Arc<dyn Runner>>;
