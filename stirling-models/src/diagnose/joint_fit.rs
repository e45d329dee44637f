//! The joint Levenberg-Marquardt fit of one candidate from one start: the strengths from the
//! one-step estimate, kept on their side of the bound, and, on records without `p_hot`, taken to
//! the fixed point of the two stages ([`settle`](crate::diagnose::joint_fit::settle)).

use super::joint::{EffectVar, Joint};
use super::score::Score;
use super::DiagnoseError;
use crate::fit::lm::{self, LmOptions};

/// Levenberg-Marquardt on the joint problem from `u0`, with the variables `fixed` held.
fn solve(joint: &Joint, u0: &[f64], fixed: &[usize], opts: &LmOptions) -> Option<lm::LmResult> {
    let mut eval = |u: &[f64]| {
        let mut u = u.to_vec();
        fixed.iter().for_each(|&i| u[i] = u0[i]);
        let (r, mut j, _) = joint.residuals(&u).ok()?;
        for &i in fixed {
            j.column_mut(i).fill(0.0);
        }
        Some((r, j))
    };
    let mut resid = |u: &[f64]| {
        let mut u = u.to_vec();
        fixed.iter().for_each(|&i| u[i] = u0[i]);
        joint.trial_residuals(&u).ok()
    };
    // trial points by their residuals alone: most are rejected (the last iterations of a
    // converged fit try up to 30 damped steps), and the sensitivities cost several runs
    let mut res = lm::minimize_split(&mut eval, Some(&mut resid), u0, opts)?;
    fixed.iter().for_each(|&i| res.x[i] = u0[i]);
    Some(res)
}

/// Fit the effect jointly: strengths start at the one-step estimate (kept on their side of
/// the bound); a bounded strength that ends below its null is held there and the fit redone.
/// `null`: the joint variables of the nominal calibration (the effect at its null), the
/// answer when every strength ends held at its null.
pub fn fit(
    joint: &Joint,
    start: &[f64],
    null: &[f64],
    score: &Score,
    opts: &LmOptions,
) -> Result<(lm::LmResult, Vec<usize>), DiagnoseError> {
    let mut u0 = start.to_vec();
    let strengths: Vec<&EffectVar> = joint.candidate().filter(|v| !v.shape).collect();
    for (v, &s) in strengths.iter().zip(&score.step) {
        // a strength the screen dropped still gets a small push to explore its side
        u0[v.index] = v.inside(if v.bounded {
            s.clamp(0.05, 2.0)
        } else {
            s.clamp(-2.0, 2.0)
        });
    }
    fit_from(joint, u0, Vec::new(), opts, Some(null))
}

/// Levenberg-Marquardt from `u0` with the variables `fixed` held; a bounded strength that
/// ends below its null is held there and the fit redone. When every strength is held, the
/// problem is the nominal calibration again: its optimum `null` is the answer, `JointBounds`
/// without it. Not a refit: on the lag record of docs/diagnosis.md the leak's two refits took
/// 11 s and, the nominal gas stage sitting in a local minimum there, one reached a lower cost
/// that the leak (held at zero) had no part in, yet was reported as the leak's fit.
fn fit_from(
    joint: &Joint,
    mut u0: Vec<f64>,
    mut fixed: Vec<usize>,
    opts: &LmOptions,
    null: Option<&[f64]>,
) -> Result<(lm::LmResult, Vec<usize>), DiagnoseError> {
    let strengths: Vec<&EffectVar> = joint.effect.iter().filter(|v| !v.shape).collect();
    for _ in 0..=strengths.len() {
        if all_held(joint, &fixed) {
            let null = null.ok_or(DiagnoseError::JointBounds)?;
            let once = LmOptions {
                max_iter: 0,
                ..*opts
            };
            let res = solve(joint, null, &fixed, &once).ok_or(DiagnoseError::JointStart)?;
            return Ok((res, fixed));
        }
        let res = solve(joint, &u0, &fixed, opts).ok_or(DiagnoseError::JointStart)?;
        let below: Vec<usize> = strengths
            .iter()
            .filter(|v| v.bounded && !fixed.contains(&v.index) && res.x[v.index] < 0.0)
            .map(|v| v.index)
            .collect();
        if below.is_empty() {
            return Ok((res, fixed));
        }
        for i in below {
            u0[i] = 0.0;
            fixed.push(i);
        }
        u0.iter_mut()
            .zip(&res.x)
            .enumerate()
            .filter(|(i, _)| !fixed.contains(i))
            .for_each(|(_, (a, b))| *a = *b);
    }
    Err(DiagnoseError::JointBounds)
}

/// Whether every strength (not the shapes) of the candidate is among the `fixed` variables:
/// the problem is then the basis's (the nominal calibration, or the last step's).
fn all_held(joint: &Joint, fixed: &[usize]) -> bool {
    joint
        .candidate()
        .filter(|v| !v.shape)
        .all(|v| fixed.contains(&v.index))
}

/// Rounds of [`settle`] at most.
const SETTLE_ROUNDS: usize = 3;
/// A round that moves no variable of the gas stage by more than this many of its standard
/// errors ends [`settle`]: the fixed point to well within the intervals the fit reports (a
/// fixed tolerance on the scaled variables, a thousandth of a parameter's starting value,
/// was below the rounds' own scatter: the quadratic regenerator friction's moves on the lag
/// record of docs/diagnosis.md went 0.04, 0.002, 0.017, 0.035, every round a whole fit).
const SETTLED: f64 = 0.2;

/// The joint fit taken to the fixed point of the two stages (records without `p_hot`, see
/// [`Joint::rebase`]): stage 1's pressure differences re-evaluated at the fitted gas stage
/// and the fit redone from its optimum, until the gas stage stops moving ([`SETTLED`]) or
/// after [`SETTLE_ROUNDS`] rounds. The rounds contract slowly where a sensor effect moved the
/// gas stage far (the lag record of docs/diagnosis.md: 18.6, 10.9, 8.9, 5.5 standard errors
/// in four rounds); three rounds, not four: the self-check's verdicts are the same
/// (docs/selfcheck-runs/run-e.md) and the fourth cost 3 s there. A round that fails (a refit
/// that cannot be integrated) leaves the problem and the fit of the round before.
pub fn settle(
    joint: &mut Joint,
    mut fit: (lm::LmResult, Vec<usize>),
    opts: &LmOptions,
) -> (lm::LmResult, Vec<usize>) {
    if !joint.has_dp_link() || all_held(joint, &fit.1) {
        return fit;
    }
    for _ in 0..SETTLE_ROUNDS {
        let mut next = joint.clone();
        let Some(refit) = settle_round(&mut next, &fit, opts) else {
            break;
        };
        let moved = next.gas_change(&fit.0.x, &refit.0.x, &refit.0.jacobian, &refit.1);
        (*joint, fit) = (next, refit);
        if moved < SETTLED {
            break;
        }
    }
    fit
}

/// One round of [`settle`]: rebase `joint` at the fit and fit again from there.
fn settle_round(
    joint: &mut Joint,
    (res, fixed): &(lm::LmResult, Vec<usize>),
    opts: &LmOptions,
) -> Option<(lm::LmResult, Vec<usize>)> {
    joint.rebase(&res.x).ok()?;
    fit_from(joint, res.x.clone(), fixed.clone(), opts, None).ok()
}
