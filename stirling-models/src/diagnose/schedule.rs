//! The order in which the screened candidates are fitted: on a few cores the run ends when
//! the slowest candidate ends, so the slowest start first (longest processing time first),
//! each candidate a task taken from one first-in first-out queue by whichever core is free.
//!
//! A candidate's expected time is its number of joint-fit starts times the time of one joint
//! evaluation measured by its screen (the gas-stage candidates, whose joint problems carry
//! both stages, come first).

use std::sync::Mutex;

use super::rank::{start_count, Assessed};
use super::screen::Screened;

/// The expected time of fitting `s` (arbitrary units, for ordering only).
fn expected(s: &Screened) -> f64 {
    s.eval_seconds * start_count(s.effect, &s.shapes) as f64
}

/// `fit` applied to every screened candidate, the slowest first, on the rayon pool; the
/// results in the order of `screened`.
pub fn longest_first<F>(screened: Vec<Screened>, fit: F) -> Vec<Assessed>
where
    F: Fn(Screened) -> Assessed + Sync,
{
    let n = screened.len();
    let mut items: Vec<(usize, Screened)> = screened.into_iter().enumerate().collect();
    items.sort_by(|a, b| expected(&b.1).total_cmp(&expected(&a.1)));
    let slots: Vec<Mutex<Option<Assessed>>> = (0..n).map(|_| Mutex::new(None)).collect();
    let (fit, slots_ref) = (&fit, &slots);
    rayon::scope_fifo(|scope| {
        for (i, s) in items {
            scope.spawn_fifo(move |_| {
                let a = fit(s);
                if let Ok(mut slot) = slots_ref[i].lock() {
                    *slot = Some(a);
                }
            });
        }
    });
    slots
        .into_iter()
        .filter_map(|m| m.into_inner().ok().flatten())
        .collect()
}
