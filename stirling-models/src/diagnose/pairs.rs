//! Pairs tried together: when no single candidate clears a step's rule but two or more are
//! significant and each of them alone makes the held-out gap worse (its single fit does not
//! lower the held-out BIC strongly), they are fitted in pairs. Two effects that each alone fit the
//! wrong shape of the gap can make the held-out error worse alone (on records of a quadratic
//! regenerator loss with a pressure lag from an independent model, each single fit left the
//! gap 13-14 times larger) and close it together.
//!
//! A leading single is also tried with a partner that lowers the held-out BIC on its own
//! ([`absorbing_pair`]): a single that absorbed its partner leaves the partner's score near
//! its null, so no later step could name it.
//!
//! A pair is named when it clears the step's rule ([`super::steps::passes`]) and each member
//! is needed: the pair lowers the held-out BIC strongly against the other member fitted alone
//! (nested models: the member alone is the pair with one strength at its null, so the BIC
//! difference on the held-out block is the evidence for the second strength).

use super::assess::joint_lm;
use super::closure;
use super::context::{Context, Eval};
use super::joint::EffectAt;
use super::rank::{self, Assessed, On};
use super::screen::screen_set;
use super::steps::{passes, Named, StepRule};
use super::types::RankEntry;
use super::verdict::STRONG_BIC;
use super::DiagnoseOptions;

/// Significant candidates paired at most (the ones with the smallest p-values): three pairs.
pub const PAIR_POOL: usize = 3;

/// The best pair of the round's significant candidates that clears the rule, if any.
pub fn best_pair(
    ctx: &Context,
    on: &On,
    assessed: &[Assessed],
    (level, rule): (f64, StepRule),
    opts: &DiagnoseOptions,
) -> Option<Named> {
    use rayon::prelude::*;
    // a candidate whose single fit already lowers the held-out BIC strongly explains part of
    // the gap on its own: it is a step's business, not a pair's (on the self-check's cubic
    // spring, outside the library, Coulomb friction alone lowered it by 194 and, paired
    // with the end stops, closed 0.92 of the gap)
    let pool = significant(assessed, level, |d| d >= STRONG_BIC, PAIR_POOL);
    let pairs: Vec<(usize, usize)> = (0..pool.len())
        .flat_map(|i| (i + 1..pool.len()).map(move |j| (i, j)))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    if let Some(progress) = ctx.progress {
        progress(&format!(
            "no single candidate closes enough: trying {} pair(s) of significant candidates together",
            pairs.len()
        ));
    }
    pairs
        .par_iter()
        .filter_map(|&(i, j)| try_pair(ctx, on, (pool[i], pool[j]), opts))
        .filter(|n| passes(&n.entry, level, rule))
        .min_by(lower_bic)
}

/// A leading single that closes this much of what remained is not tried with a partner: an
/// absorbed partner leaves more (the gain beside a leak closed 0.86), and the pairs cost
/// their fits (a single gain, closing 0.98: 10.8 s with them, 6.5 s without).
pub const LEAD_CLOSES: f64 = 0.95;

/// The leading single `lead` of a round paired with each other significant candidate that
/// lowers the held-out BIC strongly on its own (at most [`PAIR_POOL`] - 1 of them, by
/// p-value): the best pair that clears the rule, each member needed, and that closes most of
/// what `lead` alone leaves (the interval's lower end above [`super::verdict::MIN_CLOSURE`],
/// the bound of a whole explanation). Why: a single that absorbs its partner leaves the
/// partner's score near its null on its basis, so the next step cannot name it (a position
/// gain, estimated in the gas stage, took a leak's loss of pressure amplitude as `gain_x`
/// 19.7 % for 5 %, the leak's score after it not significant; paired, they closed 0.80 of
/// what the gain left). Under the steps' own bound (0.2) a pressure lag took a quadratic
/// regenerator loss beside it on a record of the lag alone (0.22 of what the lag left).
pub fn absorbing_pair(
    ctx: &Context,
    on: &On,
    lead: &Assessed,
    assessed: &[Assessed],
    (level, rule): (f64, StepRule),
    opts: &DiagnoseOptions,
) -> Option<Named> {
    use rayon::prelude::*;
    let lead_eval = lead.eval.as_ref()?;
    if lead
        .entry
        .closure_fraction
        .is_some_and(|c| c >= LEAD_CLOSES)
    {
        return None;
    }
    let pool: Vec<&Assessed> = significant(assessed, level, |d| d < STRONG_BIC, PAIR_POOL)
        .into_iter()
        .filter(|a| a.entry.effect != lead.entry.effect)
        .take(PAIR_POOL - 1)
        .collect();
    if pool.is_empty() {
        return None;
    }
    if let Some(progress) = ctx.progress {
        progress(&format!(
            "{} leads: trying it together with {}",
            lead.entry.effect,
            pool.iter()
                .map(|a| a.entry.effect.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    pool.par_iter()
        .filter_map(|other| try_pair(ctx, on, (lead, other), opts))
        .filter(|n| passes(&n.entry, level, rule))
        .filter(|n| {
            let c = closure::closure(
                ctx.data,
                lead_eval,
                &n.eval,
                ctx.hold_idx,
                ctx,
                opts.bootstrap,
                opts.seed,
            );
            c.ci_low > super::verdict::MIN_CLOSURE
        })
        .min_by(lower_bic)
}

/// The order of two named candidates by held-out BIC change (a missing one last).
fn lower_bic(a: &Named, b: &Named) -> std::cmp::Ordering {
    let d = |n: &Named| n.entry.delta_bic.unwrap_or(f64::INFINITY);
    d(a).total_cmp(&d(b))
}

/// The round's fitted candidates whose score is significant at `level` and whose held-out
/// BIC change `keep` accepts, by p-value, at most `max`.
fn significant(
    assessed: &[Assessed],
    level: f64,
    keep: impl Fn(f64) -> bool,
    max: usize,
) -> Vec<&Assessed> {
    let mut pool: Vec<&Assessed> = assessed
        .iter()
        .filter(|a| a.entry.p_value < level && a.fit.is_some() && a.eval.is_some())
        .filter(|a| a.entry.delta_bic.is_some_and(&keep))
        .collect();
    pool.sort_by(|a, b| a.entry.p_value.total_cmp(&b.entry.p_value));
    pool.truncate(max);
    pool
}

/// The pair fitted together on the basis, when each member is needed.
fn try_pair(
    ctx: &Context,
    on: &On,
    (a, b): (&Assessed, &Assessed),
    opts: &DiagnoseOptions,
) -> Option<Named> {
    let (fa, fb) = (a.fit.as_ref()?, b.fit.as_ref()?);
    let cands = [
        EffectAt {
            effect: fa.effects[0],
            shapes: fa.shapes.clone(),
        },
        EffectAt {
            effect: fb.effects[0],
            shapes: fb.shapes.clone(),
        },
    ];
    let score = screen_set(ctx, on.nominal, on.s2, on.basis, &cands).ok()?;
    let mut entry = pair_entry(&a.entry, &b.entry, &score);
    let clock = std::time::Instant::now();
    ctx.fits.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let (eval, fit) = rank::fit_set(
        ctx,
        on,
        &cands,
        &score,
        (&joint_lm(opts), rank::Mode::SIGNIFICANT),
        &mut entry,
    )
    .ok()?;
    let c = closure::closure(
        ctx.data,
        on.base_eval,
        &eval,
        ctx.hold_idx,
        ctx,
        opts.bootstrap,
        opts.seed,
    );
    (entry.closure_fraction, entry.ci_low, entry.ci_high) =
        (Some(c.fraction), Some(c.ci_low), Some(c.ci_high));
    entry.seconds = clock.elapsed().as_secs_f64();
    if let Some(progress) = ctx.progress {
        progress(&format!(
            "pair {}: held-out error {:.3}, closure {:.2} [{:.2}, {:.2}], {:.1} s",
            entry.effect, eval.holdout_error, c.fraction, c.ci_low, c.ci_high, entry.seconds
        ));
    }
    // a is needed when the pair beats b alone, and the other way round
    let needed =
        needed(ctx, &eval, b, strengths(&a.entry)) && needed(ctx, &eval, a, strengths(&b.entry));
    needed.then(|| Named {
        effects: fit.effects.clone(),
        shapes: vec![fa.shapes.clone(), fb.shapes.clone()],
        entry,
        eval,
        fit,
    })
}

/// The variables a member adds (its single fit's estimates).
fn strengths(entry: &RankEntry) -> usize {
    entry.params.len().max(1)
}

/// Whether the pair's evaluation beats `other`'s single fit (the pair without the member of
/// `k` strengths) by a strong held-out BIC change: the member is needed.
fn needed(ctx: &Context, pair: &Eval, single: &Assessed, k: usize) -> bool {
    let Some(other) = single.eval.as_ref() else {
        return false;
    };
    let n_h = ctx.holdout_points(pair) as f64;
    let d = n_h * (pair.holdout_error / other.holdout_error).ln() + k as f64 * n_h.ln();
    d < STRONG_BIC
}

/// The ranking entry of a pair (`a + b`) with its joint score.
fn pair_entry(a: &RankEntry, b: &RankEntry, score: &super::score::Score) -> RankEntry {
    RankEntry {
        score: score.stat,
        dof: score.dof,
        p_value: score.p_value,
        note: Some("a pair tried together".into()),
        ..RankEntry::named(&format!("{} + {}", a.effect, b.effect))
    }
}
