//! The verdict thresholds chosen on the tuning seeds: the score level, the held-out BIC
//! change and the closure bound of [`crate::diagnose::verdict::pick`], by grid search on the
//! tuning cases' rankings (no diagnosis is re-run). The evaluation cases are never looked at.
//!
//! The score level can only be tightened (a candidate whose score was not significant at
//! the diagnosis's level was not fitted, so a looser level has nothing to decide on).

use serde::Serialize;

use super::outcome::Outcome;
use super::plan::is_right;
use crate::diagnose::verdict::{Thresholds, MIN_CLOSURE, STRONG_BIC};

/// The tuning result.
#[derive(Clone, Debug, Serialize)]
pub struct Tuned {
    pub thresholds: Thresholds,
    /// Right verdicts and false alarms on the tuning cases under `thresholds`.
    pub right: usize,
    pub total: usize,
    pub false_alarms: usize,
    pub clean: usize,
    /// Whether any tuning case was there (without, the diagnosis's defaults are kept).
    pub tuned: bool,
}

/// The grid: score level (x1, /10, /100 of the diagnosis's), BIC change, closure bound.
fn grid(alpha: f64) -> Vec<Thresholds> {
    let mut g = Vec::new();
    for a in [alpha, alpha / 10.0, alpha / 100.0] {
        for b in [STRONG_BIC, 0.0, -2.0, -30.0] {
            for c in [MIN_CLOSURE, 0.0, 0.05, 0.1, 0.3, 0.5] {
                g.push(Thresholds {
                    alpha: a,
                    strong_bic: b,
                    min_closure: c,
                });
            }
        }
    }
    g
}

/// Score of `th` on `cases`: (right, false alarms, clean).
fn score(cases: &[&Outcome], th: &Thresholds) -> (usize, usize, usize) {
    let mut out = (0, 0, 0);
    for c in cases {
        let v = c.relabel(th);
        out.0 += usize::from(is_right(&c.expected, &v));
        if c.label == "clean" {
            out.2 += 1;
            out.1 += usize::from(v != "no_significant_gap");
        }
    }
    out
}

/// Choose the thresholds on `tune`: the most right verdicts among those whose false-alarm
/// rate is at most 5 % (if none is, the fewest false alarms first); ties keep the earlier
/// grid point, which starts at the diagnosis's defaults.
pub fn tune(tune: &[&Outcome], alpha: f64) -> Tuned {
    let defaults = Thresholds::at(alpha);
    let mut best: Option<(Thresholds, (usize, usize, usize))> = None;
    for th in grid(alpha) {
        let s = score(tune, &th);
        let key = |s: (usize, usize, usize)| {
            let ok = s.1 as f64 <= 0.05 * s.2 as f64;
            (ok, if ok { 0 } else { usize::MAX - s.1 }, s.0)
        };
        if best.is_none_or(|(_, b)| key(s) > key(b)) {
            best = Some((th, s));
        }
    }
    let (thresholds, s) = best.unwrap_or((defaults, (0, 0, 0)));
    Tuned {
        thresholds: if tune.is_empty() {
            defaults
        } else {
            thresholds
        },
        right: s.0,
        total: tune.len(),
        false_alarms: s.1,
        clean: s.2,
        tuned: !tune.is_empty(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_starts_at_the_defaults() {
        let g = grid(0.01);
        assert_eq!(g[0], Thresholds::at(0.01));
        assert!(g.iter().all(|t| t.alpha <= 0.01));
    }

    #[test]
    fn no_tuning_cases_keep_the_defaults() {
        let t = tune(&[], 0.01);
        assert_eq!(t.thresholds, Thresholds::at(0.01));
        assert!(!t.tuned);
    }
}
