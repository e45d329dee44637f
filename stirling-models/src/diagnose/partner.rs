//! A partner beside seen end stops: an effect on the engine's dynamics that the one-run pass
//! found, named after the stops of the second pass (docs/diagnosis.md, "A partner beside the
//! stops, named from the one-run pass").
//!
//! Why from the one-run pass: the second pass restarts stage 1 every quarter cycle from the
//! measured body states, which hides what builds up over cycles (a loss's lost stroke), so
//! a quadratic regenerator loss beside the stops screens at p 5e-3 to 0.2 there and is not
//! named. On the one-run pass it is plain: score p 1.9e-5 to 8e-11, its fit lowering the
//! held-out BIC by 25 to 30 (the record at 1.9e-5, just above the level, keeps the stops
//! alone); the stops alone give no candidate a p-value below 1.6e-4 there
//! and no model effect a BIC change beyond -7 (the self-check's single stops records).
//! Both tests together name it: a score beyond what the stops' clipping produces
//! ([`PARTNER_P`](crate::diagnose::partner::PARTNER_P)) and a fit that is strongly better on
//! the held-out block ([`STRONG_BIC`](crate::diagnose::verdict::STRONG_BIC)). Its closure is
//! of the one-run gap, which the stops dominate (a few thousandths); the step says so, and
//! adds nothing to the cumulative closure.
//!
//! Only effects on the model's dynamics without travels qualify: a sensor effect is tested
//! by the restarted pass itself (a pressure lag is named there beside the stops), and a
//! position gain beside a cause outside the library reached p 9e-11 and a BIC change of -21
//! on one run (`end_stops` + the speed-dependent heat transfer), with no gain present.

use super::screen::has_travel;
use super::types::{Diagnosis, Interval, RankEntry, Step};
use super::verdict::STRONG_BIC;
use crate::effects::{EffectInfo, EffectTarget};

/// The one-run score p-value a partner must beat: the least one the stops alone gave any
/// candidate on the tuning seed's single stops records (1.6e-4, a pressure lag), over ten.
pub const PARTNER_P: f64 = 1.6e-5;

/// The one-run score p-value that names a partner on its score alone, whatever its one-run
/// fit does on the held-out block: the geometric middle, on the self-check's tuning seed,
/// between the largest p-value a true partner gave (4.7e-12, Coulomb friction beside the
/// stops) and the least one an absent model effect gave on any record whose stops were named
/// (1.1e-6, Coulomb friction beside a position gain and the cubic spring). Why the held-out
/// evidence is not asked for then: the one-run model has no stops (one run cannot follow a
/// body between them), so a partner's one-run fit is judged on a held-out block the stops'
/// misfit dominates; Coulomb friction beside the stops lowered no held-out BIC there (+11 to
/// +23) while its score was 5e-12 to 7e-18.
pub const PARTNER_SCORE_P: f64 = 2.3e-9;

/// Whether a one-run entry names a partner: a model effect without travels, fitted off its
/// null, under [`passes`].
pub fn qualifies(e: &RankEntry, info: &EffectInfo) -> bool {
    info.target == EffectTarget::Model
        && !has_travel(info)
        && e.fitted
        && e.moved
        && passes(e.p_value, e.delta_bic, STRONG_BIC)
}

/// The rule on a partner's one-run score `p` and held-out BIC change, at the BIC bar
/// `strong_bic` (the self-check tunes it): a score below [`PARTNER_P`] with a held-out BIC
/// change below the bar, or a score below [`PARTNER_SCORE_P`] alone.
pub fn passes(p: f64, delta_bic: Option<f64>, strong_bic: f64) -> bool {
    p < PARTNER_SCORE_P || p < PARTNER_P && delta_bic.is_some_and(|d| d < strong_bic)
}

/// Whether a partner was named on its score alone (its one-run fit not strongly better on
/// the held-out block): its one-run estimate is then no measure of its strength.
pub fn on_score_alone(p: f64, delta_bic: Option<f64>) -> bool {
    p < PARTNER_SCORE_P && !delta_bic.is_some_and(|d| d < STRONG_BIC)
}

/// Add the partners of `first` (the one-run pass) to `second` (a second pass that named the
/// stops), each as a step of its own; `infos`: the candidates. Returns the one-run entries
/// named.
pub fn name<'f>(
    second: &mut Diagnosis,
    first: &'f Diagnosis,
    infos: &[&EffectInfo],
) -> Vec<&'f RankEntry> {
    let info = |name: &str| infos.iter().copied().find(|i| i.name == name);
    let found: Vec<&RankEntry> = first
        .ranking
        .iter()
        .filter(|e| !second.verdict.effects.contains(&e.effect))
        .filter(|e| info(&e.effect).is_some_and(|i| qualifies(e, i)))
        .collect();
    for e in &found {
        let step = step_of(e, second.steps.last(), second.steps.len() + 1);
        second.steps.push(step);
        second.verdict.effects.push(e.effect.clone());
    }
    found
}

/// The step of a partner: its one-run estimates, score, BIC change and closure of the
/// one-run gap; the cumulative closure and held-out errors stay the last step's (`last`),
/// which the partner's one-run fit does not change.
fn step_of(e: &RankEntry, last: Option<&Step>, index: usize) -> Step {
    let closure = Interval {
        value: e.closure_fraction.unwrap_or(f64::NAN),
        ci_low: e.ci_low.unwrap_or(f64::NAN),
        ci_high: e.ci_high.unwrap_or(f64::NAN),
    };
    Step::one_run_of(
        e,
        (last, index),
        closure,
        "named on the one-run pass beside the end stops: no simulated gap of its own",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_partner_needs_both_a_score_beyond_the_stops_and_a_strong_bic() {
        // the quadratic loss beside the stops (self-check seeds 5, 1005, 1006)
        assert!(passes(8.4e-11, Some(-25.0), STRONG_BIC));
        assert!(passes(2.7e-6, Some(-27.0), STRONG_BIC));
        // the single stops records: the loss's spurious score and fit
        assert!(!passes(4.2e-4, Some(-6.0), STRONG_BIC));
        // a score far beyond anything absent effects gave, without the held-out evidence
        // (Coulomb friction beside the stops, whose one-run fit lacks them)
        assert!(passes(6.8e-12, Some(17.0), STRONG_BIC));
        assert!(on_score_alone(6.8e-12, Some(17.0)));
        assert!(!on_score_alone(8.4e-11, Some(-25.0)));
        // beyond the level but not that far, without the held-out evidence: Coulomb beside
        // the speed-dependent heat transfer (outside the library) and the stops
        assert!(!passes(1.7e-7, Some(3.0), STRONG_BIC));
        assert!(!passes(1e-8, None, STRONG_BIC));
        // held-out evidence without the score
        assert!(!passes(1.6e-4, Some(-108.0), STRONG_BIC));
    }

    #[test]
    fn a_partner_step_keeps_the_last_cumulative_closure_and_says_where_it_was_named() {
        let mut e = RankEntry::named("regen_quadratic");
        e.p_value = 8.4e-11;
        e.delta_bic = Some(-25.0);
        e.closure_fraction = Some(0.007);
        let stops = Interval {
            value: 0.87,
            ci_low: 0.78,
            ci_high: 0.91,
        };
        let mut last = step_of(&RankEntry::named("end_stops"), None, 1);
        (last.one_run, last.cumulative, last.holdout_error) = (false, stops, 2.09);
        let s = step_of(&e, Some(&last), 2);
        assert_eq!((s.step, s.p_value, s.delta_bic), (2, 8.4e-11, -25.0));
        assert_eq!(s.closure.value, 0.007);
        assert_eq!(s.cumulative.value, stops.value);
        assert_eq!(s.holdout_error, 2.09);
        assert_eq!(s.label(), "regen_quadratic (one-run pass)");
        assert_eq!(last.label(), "end_stops");
    }
}
