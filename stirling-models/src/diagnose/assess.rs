//! One round of candidates on a basis (the nominal calibration, or the effects accepted by the
//! steps so far): screen every candidate at its null, fit the significant ones jointly with
//! the basis, rank them and attach each fitted one's closure of the basis's held-out gap.

use std::time::Instant;

use super::context::{Context, Eval};
use super::rank::{self, On};
use super::steps::RESET_P;
use super::{closure, schedule, screen, DiagnoseOptions};
use crate::effects::{EffectInfo, EffectTarget};
use crate::fit::lm::LmOptions;

/// A joint fit stops when an accepted step lowers the cost (half the chi-square of the
/// weighted residuals, which have unit variance) by less than this: 1/50 of the held-out BIC
/// change a verdict needs ([`super::verdict::STRONG_BIC`], in -2 log likelihood). On the lag
/// record of docs/diagnosis.md the fits' last iterations gained 0.01 to 0.3 each.
const JOINT_FATOL: f64 = 0.1;

/// The Levenberg-Marquardt options of the joint fits.
pub fn joint_lm(opts: &DiagnoseOptions) -> LmOptions {
    let mut lm = opts.fit.lm;
    lm.max_iter = opts.joint_iters;
    // trial steps of at most one typical strength: far trials (an engine stopped by friction)
    // are slow to integrate and rejected anyway
    lm.max_step = 1.0;
    lm.fatol = JOINT_FATOL;
    lm
}

/// Screen every candidate on the basis, fit the significant ones, rank them and attach the
/// closure of each fitted one. The candidates are independent: one per core.
///
/// Only a significant candidate can be named ([`super::verdict::pick`]; the self-check's
/// tuning can only tighten the level), and the significant ones rank ahead of every other,
/// so fitting the others changes no verdict: they are fitted with `fit_all` only (for the
/// report). `level`: the per-candidate significance level.
pub fn assess_all(
    ctx: &Context,
    on: &On,
    cands: &[&'static EffectInfo],
    (opts, level): (&DiagnoseOptions, f64),
    (absorbed, clock): (bool, Instant),
) -> Vec<rank::Assessed> {
    use rayon::prelude::*;
    let lm = joint_lm(opts);
    let screened: Vec<screen::Screened> = cands
        .par_iter()
        .map(|e| screen::screen_candidate(ctx, on.nominal, on.s2, on.basis, e))
        .collect();
    // a later round on a calibration that absorbed something: a model effect whose score
    // is near significance is also fitted from the reset start (`steps::RESET_P`)
    let later = absorbed && !ctx.restarted && !on.basis.effects.is_empty();
    let from_reset = |s: &screen::Screened| {
        later
            && !s.significant(level)
            && s.entry.p_value < RESET_P
            && s.effect.target == EffectTarget::Model
            && !screen::has_travel(s.effect)
    };
    // beside seen end stops every candidate without travels is judged on the channels the
    // stops do not touch (`untouched`), whatever its score, on the nominal calibration
    let untouched = on.basis.effects.is_empty() && super::untouched::has_gap(ctx, on.base_eval);
    let beside_stops = |s: &screen::Screened| untouched && !screen::has_travel(s.effect);
    let fit = |s: &screen::Screened| {
        opts.fit_all || s.significant(level) || from_reset(s) || beside_stops(s)
    };
    report(opts, || {
        let sig = screened.iter().filter(|s| s.significant(level)).count();
        let fitted = screened.iter().filter(|s| fit(s)).count();
        screen_line(screened.len(), (sig, fitted, level), absorbed, opts, clock)
    });
    let mut assessed = schedule::longest_first(screened, |s| {
        if fit(&s) {
            let mode = rank::Mode {
                significant: s.significant(level),
                from_reset: from_reset(&s),
            };
            rank::assess(ctx, on, s, &lm, mode)
        } else {
            s.unfitted("not fitted: its score is not significant (--fit-all fits it)")
        }
    });
    rank::sort(&mut assessed, level);
    attach_closures(ctx, on.base_eval, &mut assessed, (opts, untouched));
    assessed
}

/// A progress line, when the caller asked for them.
pub fn report(opts: &DiagnoseOptions, line: impl FnOnce() -> String) {
    if let Some(progress) = opts.progress {
        progress(&line());
    }
}

/// The progress line after the screen: how many candidates are significant, how many are
/// fitted, and why more are fitted than are significant.
fn screen_line(
    screened: usize,
    (sig, fitted, level): (usize, usize, f64),
    absorbed: bool,
    opts: &DiagnoseOptions,
    clock: Instant,
) -> String {
    let why = if opts.fit_all {
        " (--fit-all)"
    } else if absorbed && fitted < screened {
        " (the calibration moved a parameter beyond 2 prior sd: an effect may be absorbed there; --fit-all fits the others too)"
    } else {
        ""
    };
    format!(
        "screened {screened} candidates ({:.1} s): {sig} significant at {level:.1e}; fitting {fitted}{why}",
        clock.elapsed().as_secs_f64(),
    )
}

/// The closure, with its interval, of the basis's held-out gap by every fitted candidate
/// (and beside seen end stops, of the gap on the channels they do not touch).
fn attach_closures(
    ctx: &Context,
    base: &Eval,
    assessed: &mut [rank::Assessed],
    (opts, untouched): (&DiagnoseOptions, bool),
) {
    for a in assessed.iter_mut() {
        if let Some(ev) = &a.eval {
            let c = closure::closure(
                ctx.data,
                base,
                ev,
                ctx.hold_idx,
                ctx,
                opts.bootstrap,
                opts.seed,
            );
            a.entry.closure_fraction = Some(c.fraction);
            a.entry.ci_low = Some(c.ci_low);
            a.entry.ci_high = Some(c.ci_high);
            if untouched {
                a.entry.untouched = super::untouched::closure_on(ctx, base, ev, opts);
            }
        }
    }
}
