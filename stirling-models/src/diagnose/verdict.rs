//! The verdict: the leading effect, `unexplained`, or `no_significant_gap`.
//!
//! - `effect`: the first-ranked candidate was fitted, its score is significant at the family-wise
//!   level `alpha` (Bonferroni over the candidates), it lowers the held-out BIC by more than 10,
//!   and its closure interval lies above `MIN_CLOSURE`;
//! - `unexplained`: some candidate is significant, but none closes a significant part of the
//!   gap;
//! - `no_significant_gap`: no candidate's score is significant: no omitted direction shows a
//!   systematic deviation beyond the noise (output noise and the input noise driven through the
//!   subsystems, see [`crate::diagnose::score`]). The held-out BIC alone does not count: on clean
//!   data an added damping (friction) can lower the held-out error by damping the response to input
//!   noise, which is not a gap of the model. The reason names the parameters the calibration moved
//!   by more than [`SHIFT_NOTE_SD`](crate::diagnose::verdict::SHIFT_NOTE_SD) prior standard
//!   deviations (a gap the parameters absorbed) and the leading candidate that fits with them
//!   nearer their estimates.

use serde::Serialize;

use super::context::Eval;
pub use super::types::Verdict;
use super::types::{ParamShift, RankEntry, Step};

/// The lower closure bound a winner must clear. Chosen on the verdict self-checks of
/// docs/diagnosis.md (34 records, `nsection` n = 2, `p,x,y`): the library effects named
/// right had closure lower bounds of 0.80 to 0.99 (engines that still ran), the causes
/// outside the library reached 0.30 (`h_speed`, named `leak` under the earlier bound of
/// 0.2) and 0.07 (`spring_cubic`); 0.5 lies between with room on both sides.
pub const MIN_CLOSURE: f64 = 0.5;
/// A nominal held-out error (in noise variances) beyond which a record is never read as
/// `no_significant_gap`, whatever the scores say: the model misses it grossly, and no library
/// direction sees why (a cause outside the library, or a record that is not what the model
/// measures: swapped or sign-flipped channels). Clean records stay under 10 (the input noise
/// driven through the displacer's resonance raises `x` to 5-9 noise variances on `nsection`);
/// the swapped-channel record of issue 38 reached 4733.
pub const GROSS_GAP: f64 = 25.0;
/// The held-out BIC change that counts as an improvement ("strong evidence", Kass-Raftery).
pub const STRONG_BIC: f64 = -10.0;
/// A channel whose held-out rms after the named effects is more than this many times its
/// noise level leaves a remainder, whether or not a library candidate is still significant
/// on it (four noise variances in that channel). Read off the self-check's tuning seeds
/// (docs/diagnosis.md, "An effect beside a cause outside the library"): after the right
/// single effects every channel stayed at or under 1.77 (the lag's `p`), except the end
/// stops' `y` (3.04, flagged: the fitted contact leaves it); beside a cause outside the
/// library the channel it acts on stayed at 2.9 to 4.9 (`p` beside the speed-dependent heat
/// transfer, `x` and `y` beside hardening springs), where no candidate was significant.
pub const REMAINDER_RATIO: f64 = 2.0;

/// Calibrated parameters further than this from their estimates (prior standard deviations)
/// are named in the verdict.
pub const SHIFT_NOTE_SD: f64 = 2.0;

/// A note on parameters the calibration moved far: the gap may hide in them.
fn shift_note(shifts: &[ParamShift], top: Option<&RankEntry>) -> String {
    let far: Vec<String> = shifts
        .iter()
        .filter(|s| s.prior_sd.is_some_and(|z| z.abs() > SHIFT_NOTE_SD))
        .map(|s| {
            format!(
                "{} x{:.2} ({:+.1} prior sd)",
                s.name,
                s.factor,
                s.prior_sd.unwrap_or(f64::NAN)
            )
        })
        .collect();
    if far.is_empty() {
        return String::new();
    }
    let lead = top
        .filter(|t| t.fitted && t.delta_bic.is_some_and(|d| d < 0.0))
        .map(|t| {
            format!(
                "; the leading candidate `{}` fits with them nearer their estimates",
                t.effect
            )
        })
        .unwrap_or_default();
    format!(
        "; but the calibration moved {} from the estimates: an omitted effect may be absorbed by them{lead}",
        far.join(", ")
    )
}

/// The thresholds of the verdict rule (the self-check tunes them on its tuning seeds).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Thresholds {
    /// Family-wise significance level of the score (Bonferroni over the candidates).
    pub alpha: f64,
    /// Held-out BIC change a winner must beat (negative).
    pub strong_bic: f64,
    /// Lower closure bound a winner must clear.
    pub min_closure: f64,
}

impl Thresholds {
    /// The diagnosis's rule at significance level `alpha`.
    pub fn at(alpha: f64) -> Self {
        Self {
            alpha,
            strong_bic: STRONG_BIC,
            min_closure: MIN_CLOSURE,
        }
    }
}

/// Which verdict the rule gives (the reasons are [`decide`]'s).
#[derive(Clone, Copy, Debug)]
pub enum Pick<'a> {
    Effect(&'a RankEntry),
    NoSignificantGap,
    Unexplained,
}

/// The verdict rule on a ranking of `candidates` candidates, for a nominal model whose
/// held-out error is `gap` noise variances.
pub fn pick<'a>(
    ranking: &'a [RankEntry],
    candidates: usize,
    gap: f64,
    th: &Thresholds,
) -> Pick<'a> {
    let level = th.alpha / candidates.max(1) as f64;
    if let Some(t) = ranking.first().filter(|t| {
        t.fitted
            && t.p_value < level
            && t.delta_bic.is_some_and(|d| d < th.strong_bic)
            && t.ci_low.is_some_and(|c| c > th.min_closure)
    }) {
        return Pick::Effect(t);
    }
    if ranking.iter().any(|r| r.p_value < level) || gap > GROSS_GAP {
        Pick::Unexplained
    } else {
        Pick::NoSignificantGap
    }
}

/// Decide from the ranking.
pub fn decide(
    ranking: &[RankEntry],
    nominal: &Eval,
    alpha: f64,
    candidates: usize,
    shifts: &[ParamShift],
) -> Verdict {
    let level = alpha / candidates.max(1) as f64;
    let significant = ranking.iter().filter(|r| r.p_value < level).count();
    let better = ranking
        .iter()
        .filter(|r| r.delta_bic.is_some_and(|d| d < STRONG_BIC))
        .count();
    let top = ranking.first();
    let mk = |v: &str, r: Option<&RankEntry>, reason: String| Verdict {
        verdict: v.into(),
        effect: r.map(|r| r.effect.clone()),
        effects: r
            .filter(|_| v == "effect")
            .map(|r| vec![r.effect.clone()])
            .unwrap_or_default(),
        unexplained_remainder: v == "unexplained",
        free_run_worse: false,
        closure_fraction: r.and_then(|r| r.closure_fraction),
        ci_low: r.and_then(|r| r.ci_low),
        ci_high: r.and_then(|r| r.ci_high),
        gap: nominal.holdout_error,
        reason,
    };
    match pick(ranking, candidates, nominal.holdout_error, &Thresholds::at(alpha)) {
        Pick::Effect(t) => mk("effect", Some(t), format!("`{}`: score p = {:.2e} < {:.1e}, held-out BIC change {:.1}, closure {:.2} [{:.2}, {:.2}]", t.effect, t.p_value, level, t.delta_bic.unwrap_or(f64::NAN), t.closure_fraction.unwrap_or(f64::NAN), t.ci_low.unwrap_or(f64::NAN), t.ci_high.unwrap_or(f64::NAN))),
        Pick::NoSignificantGap => {
            let mut reason = format!("no candidate is significant at {level:.1e} ({better} lower the held-out BIC by more than {}; held-out error {:.3} noise variances)", -STRONG_BIC, nominal.holdout_error);
            reason.push_str(&shift_note(shifts, top));
            mk("no_significant_gap", None, reason)
        }
        Pick::Unexplained if significant == 0 => mk("unexplained", None, format!("the calibrated model misses the held-out block by {:.1} noise variances (more than {GROSS_GAP}), yet no library effect's score is significant at {level:.1e}: the cause lies outside the library, or the record is not what the model measures (swapped or sign-flipped channels, a wrong unit)", nominal.holdout_error)),
        Pick::Unexplained => {
            let r = top.filter(|t| t.fitted);
            mk("unexplained", r, format!("{significant} candidate(s) significant, {better} lower the held-out BIC, but none closes more than {MIN_CLOSURE} of the gap with confidence"))
        }
    }
}

/// Decide from the steps of the explanation (`last`: the round after the last step that
/// named nothing more); without steps, from the first round's `ranking` ([`decide`]).
///
/// The named effects are the verdict when the whole chain closes a significant part of the
/// nominal gap: the lower bound of its cumulative closure clears [`MIN_CLOSURE`], the bound a
/// single effect had to clear. A chain of effects that each close a little (a cause outside the
/// library explained away in pieces) stays `unexplained`. A remainder is reported when a
/// candidate of the last round is still significant: a systematic deviation is left that no
/// library effect closes.
pub fn decide_steps(
    (steps, ranking, last): (&[Step], &[RankEntry], &[RankEntry]),
    nominal: &Eval,
    alpha: f64,
    candidates: usize,
    shifts: &[ParamShift],
) -> Verdict {
    let Some(end) = steps.last() else {
        return decide(ranking, nominal, alpha, candidates, shifts);
    };
    let level = alpha / candidates.max(1) as f64;
    let named: Vec<String> = steps
        .iter()
        .filter(|s| s.superseded.is_none())
        .flat_map(|s| s.effects.clone())
        .collect();
    let cum = end.cumulative;
    let chain = steps
        .iter()
        .map(|s| {
            format!(
                "`{}` closes {:.2} [{:.2}, {:.2}] of what remained (p {:.1e}, BIC {:.0}{}{})",
                s.effects.join("` + `"),
                s.closure.value,
                s.closure.ci_low,
                s.closure.ci_high,
                s.p_value,
                s.delta_bic,
                if s.from_reset {
                    ", fitted from the nominal parameters' estimates: the calibration had absorbed it"
                } else {
                    ""
                },
                s.superseded
                    .as_ref()
                    .map_or(String::new(), |x| format!("; {}", x.reason))
            )
        })
        .collect::<Vec<_>>()
        .join("; then ");
    let total = format!(
        "together {:.2} [{:.2}, {:.2}] of the gap (held-out error {:.3} -> {:.3} noise variances)",
        cum.value, cum.ci_low, cum.ci_high, nominal.holdout_error, end.holdout_error
    );
    let base = Verdict {
        verdict: String::new(),
        effect: named.first().cloned(),
        effects: Vec::new(),
        unexplained_remainder: true,
        free_run_worse: false,
        closure_fraction: Some(cum.value),
        ci_low: Some(cum.ci_low),
        ci_high: Some(cum.ci_high),
        gap: nominal.holdout_error,
        reason: String::new(),
    };
    if !(cum.ci_low > MIN_CLOSURE) {
        return Verdict {
            verdict: "unexplained".into(),
            reason: format!("{chain}: {total}, not more than {MIN_CLOSURE} with confidence: the library does not explain the gap"),
            ..base
        };
    }
    let left: Vec<&str> = last
        .iter()
        .filter(|r| r.p_value < level)
        .map(|r| r.effect.as_str())
        .collect();
    let missed: Vec<String> = end
        .channels
        .iter()
        .filter(|c| c.ratio > REMAINDER_RATIO)
        .map(|c| format!("`{}` at {:.2} times its noise", c.channel, c.ratio))
        .collect();
    let remainder = !left.is_empty() || !missed.is_empty();
    let tail = match (left.is_empty(), missed.is_empty()) {
        (false, _) => format!("; a gap remains that the library does not explain ({} still significant at {level:.1e}, none closes a significant part)", left.join(", ")),
        (true, false) => format!("; a gap remains that the library does not explain: no candidate is significant at {level:.1e} on what remains, but the held-out block is still missed by more than {REMAINDER_RATIO} times the noise ({})", missed.join(", ")),
        (true, true) => format!("; no candidate is significant at {level:.1e} on what remains"),
    };
    Verdict {
        verdict: "effect".into(),
        effects: named,
        unexplained_remainder: remainder,
        free_run_worse: false,
        reason: format!("{chain}: {total}{tail}"),
        ..base
    }
}
