//! A stop request for the work in progress: an interactive front end (the Python module on
//! Ctrl-C) sets it, and every step loop ([`integrate()`](crate::sim::integrate()) and the
//! sensitivity run) ends at its next accepted step with [`SimError::Interrupted`].
//!
//! The request is process-wide, as the signal that usually causes it is: every simulation
//! running in the process stops, including those an analysis runs on other threads (a
//! diagnosis's candidates, a sweep's points). An analysis that records a failed simulation and
//! carries on (a sweep point, a diagnosis candidate) meets the request again at its next
//! simulation, so it winds down within a step of each; the caller that made the request
//! [`clear`](crate::sim::interrupt::clear)s it before the next piece of work.

use std::sync::atomic::{AtomicBool, Ordering};

use super::SimError;

static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Ask every running simulation to stop at its next step.
pub fn request() {
    REQUESTED.store(true, Ordering::SeqCst);
}

/// Withdraw the request (before starting new work).
pub fn clear() {
    REQUESTED.store(false, Ordering::SeqCst);
}

/// Whether a stop is requested.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::Relaxed)
}

/// `Err(SimError::Interrupted)` at time `t` when a stop is requested.
pub(crate) fn check(t: f64) -> Result<(), SimError> {
    if requested() {
        Err(SimError::Interrupted { t })
    } else {
        Ok(())
    }
}
