//! An effect beside seen end stops, judged on the channels the stops do not touch
//! (docs/diagnosis.md, "The channels the stops do not touch").
//!
//! The calibration runs in stages: the mechanics (stage 1) driven by the measured pressure,
//! the gas (stage 2) driven by the measured positions. End stops act on a body, so a stage
//! driven by the measured positions cannot misfit because of them: whatever gap the gas
//! stage's channel (`p`) carries beside seen stops is another effect's. On one run, though,
//! a candidate's closure is taken over every channel, where the stops' misfit of the
//! clipped body dominates (14 to 16 noise sd on `y`), so a leak that takes the gas channel
//! from 4.7-6.3 to 1.01-1.03 noise sd closes nothing of the whole; and its score at the null
//! says nothing either (p 0.3 to 1.0: the calibration took the leak into the regenerator
//! friction, at the basis's optimum its score is near its null).
//!
//! So beside seen stops every candidate without travels is fitted on the one-run pass and
//! its closure taken on the untouched channels alone. The one that closes the most is named
//! when those channels carry a gap
//! ([`UNTOUCHED_GAP`](crate::diagnose::untouched::UNTOUCHED_GAP)) and the lower bound of
//! its closure clears the verdict's [`MIN_CLOSURE`](crate::diagnose::verdict::MIN_CLOSURE).
//! Measured on the 27 stop records of the two-seed self-check (docs/diagnosis.md): without
//! a gas-side effect the gas channel sits at 1.00-1.04 noise sd (1.08 noise variances at
//! most); beside a leak, a position gain or a pressure lag at 4.0 to 7.1 sd, each closed to
//! 1.0-1.4 by the true effect and by no other as far; beside the speed-dependent heat
//! transfer (outside the library) at 2.1 sd, which no candidate closes by a tenth.

use super::closure;
use super::context::{Context, Eval, Prediction};
use super::screen::has_travel;
use super::stops_equation::StopSide;
use super::types::{EffectEstimate, Evidence, Interval, RankEntry, Step, UntouchedClosure};
use super::verdict::MIN_CLOSURE;
use super::DiagnoseOptions;
use crate::effects::EffectInfo;

/// The untouched channels' held-out error at the nominal calibration, in noise variances,
/// from which they carry a gap: twice the noise floor. Beside seen stops without a gas-side
/// effect they sat at 1.08 at most; beside the outside cause at 4.2 to 4.5 (closed by no
/// candidate); beside a gas-side effect at 16 to 50.
pub const UNTOUCHED_GAP: f64 = 2.0;

/// The channels of the stages (`stage_preds`, per stage) that predict no body whose stops
/// are `seen`; empty when none are seen.
pub fn channels(stage_preds: &[Vec<Prediction>], seen: &[StopSide]) -> Vec<String> {
    if seen.is_empty() {
        return Vec::new();
    }
    stage_preds
        .iter()
        .filter(|st| {
            !st.iter()
                .any(|p| seen.iter().any(|s| s.channel == p.channel))
        })
        .flat_map(|st| st.iter().map(|p| p.channel.clone()))
        .collect()
}

/// `ev` restricted to the channels `keep`.
fn restricted(ev: &Eval, keep: &[String]) -> Eval {
    let pick = |v: &[Vec<f64>]| -> Vec<Vec<f64>> {
        ev.channels
            .iter()
            .zip(v)
            .filter(|(c, _)| keep.contains(c))
            .map(|(_, r)| r.clone())
            .collect()
    };
    Eval {
        channels: ev
            .channels
            .iter()
            .filter(|c| keep.contains(c))
            .cloned()
            .collect(),
        resid: pick(&ev.resid),
        hp: pick(&ev.hp),
        pred: pick(&ev.pred),
        ..ev.clone()
    }
}

/// Whether the untouched channels of `ctx` carry a gap at `base` (the nominal calibration):
/// their held-out error, in noise variances, from [`UNTOUCHED_GAP`]. Without it no candidate
/// can be named on them, and none is fitted for them.
pub fn has_gap(ctx: &Context, base: &Eval) -> bool {
    if ctx.untouched.is_empty() {
        return false;
    }
    let b = restricted(base, &ctx.untouched);
    let (lo, hi) = ctx.hold_idx;
    let err: f64 = b
        .channels
        .iter()
        .zip(&b.hp)
        .map(|(c, r)| {
            r[lo..hi]
                .iter()
                .map(|v| (v / ctx.noise_of(c)).powi(2))
                .sum::<f64>()
        })
        .sum();
    let n = (b.channels.len() * (hi - lo)) as f64;
    n > 0.0 && err / n >= UNTOUCHED_GAP
}

/// The closure of `base`'s held-out gap by `ev` on the untouched channels of `ctx`, with its
/// interval; `None` when there are none (no stops seen, or the restarted pass).
pub fn closure_on(
    ctx: &Context,
    base: &Eval,
    ev: &Eval,
    opts: &DiagnoseOptions,
) -> Option<UntouchedClosure> {
    if ctx.untouched.is_empty() {
        return None;
    }
    let (b, a) = (
        restricted(base, &ctx.untouched),
        restricted(ev, &ctx.untouched),
    );
    if b.channels.is_empty() {
        return None;
    }
    let c = closure::closure(
        ctx.data,
        &b,
        &a,
        ctx.hold_idx,
        ctx,
        opts.bootstrap,
        opts.seed,
    );
    Some(UntouchedClosure {
        channels: b.channels,
        before: c.err_before,
        after: c.err_after,
        closure: Interval {
            value: c.fraction,
            ci_low: c.ci_low,
            ci_high: c.ci_high,
        },
    })
}

/// Whether an entry's untouched closure names it: a gap on those channels and a closure
/// whose lower bound clears [`MIN_CLOSURE`].
pub fn clears(u: &UntouchedClosure) -> bool {
    u.before >= UNTOUCHED_GAP && u.closure.ci_low > MIN_CLOSURE
}

/// The entry of the one-run pass's first round (`ranking`) without travels that closes the
/// most of the untouched channels' gap, when it clears the rule ([`clears`]); `infos`: the
/// candidates.
pub fn best<'f>(ranking: &'f [RankEntry], infos: &[&EffectInfo]) -> Option<&'f RankEntry> {
    let no_travel = |name: &str| infos.iter().any(|i| i.name == name && !has_travel(i));
    ranking
        .iter()
        .filter(|e| e.fitted && e.moved && no_travel(&e.effect))
        .filter_map(|e| e.untouched.as_ref().map(|u| (e, u.closure.value)))
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(e, _)| e)
        .filter(|e| e.untouched.as_ref().is_some_and(clears))
}

/// The step of an effect named on the untouched channels: its one-run estimates, score
/// and BIC change, its closure of those channels' gap; the cumulative closure and held-out
/// errors stay the last step's (`last`).
pub fn step_of(e: &RankEntry, last: Option<&Step>, index: usize) -> Step {
    let closure = e.untouched.as_ref().map_or(Interval::NAN, |u| u.closure);
    Step {
        evidence: Evidence::Untouched,
        ..Step::one_run_of(
            e,
            (last, index),
            closure,
            "named on the one-run pass beside the end stops, on the channels they do not touch: its closure is of those channels' gap",
        )
    }
}

/// The step of end stops named from the measured acceleration alone (`seen`): per side, the
/// travel and the hinge's coefficient (`-kc / m`, 1/s^2) of the equation-error fit, without
/// intervals: the smoothing blunts the contact, so the travel lies 0.05 to 0.1 mm inside the
/// truth and the coefficient reads 0.6 to 0.8 of it (docs/diagnosis.md), a bias no interval
/// of the regression would cover.
pub fn seen_step(name: &str, seen: &[StopSide]) -> Step {
    let est = |name: String, value: f64, unit: &str| EffectEstimate {
        name,
        value,
        std_error: f64::NAN,
        ci_low: f64::NAN,
        ci_high: f64::NAN,
        unit: unit.into(),
    };
    let params = seen
        .iter()
        .flat_map(|s| {
            [
                est(format!("travel_{}", s.channel), s.travel, "m"),
                est(format!("hinge_{}", s.channel), s.coefficient, "1/s^2"),
            ]
        })
        .collect();
    Step {
        params,
        simulation_gap_note: Some(
            "named from the measured acceleration alone: the model with the stops does not close the held-out gap, no simulated closure is claimed".into(),
        ),
        evidence: Evidence::Acceleration,
        ..Step::of_entry(&RankEntry::named(name))
    }
}

/// How an effect named on the untouched channels reads in a verdict's reason.
pub fn reason(e: &RankEntry) -> String {
    let Some(u) = &e.untouched else {
        return String::new();
    };
    format!(
        "beside the stops, `{}` named on the one-run pass on the channels the stops do not touch ({}, driven by the measured positions): it takes their held-out error from {:.2} to {:.2} noise variances, closure {:.3} [{:.3}, {:.3}] (a gap there from {UNTOUCHED_GAP} noise variances, a closure bound above {MIN_CLOSURE}); its score at the calibration was p {:.1e}",
        e.effect,
        u.channels.join(", "),
        u.before,
        u.after,
        u.closure.value,
        u.closure.ci_low,
        u.closure.ci_high,
        e.p_value,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::EFFECTS;

    fn pred(channel: &str) -> Prediction {
        Prediction {
            channel: channel.into(),
            first: 0,
            values: Vec::new(),
            drift_rate: 0.0,
        }
    }

    fn side(channel: &str) -> StopSide {
        StopSide {
            channel: channel.into(),
            side: 1,
            travel: 4.45e-3,
            coefficient: -4e5,
            share: 0.1,
            beyond: 100,
        }
    }

    #[test]
    fn the_untouched_channels_are_those_of_the_stages_that_predict_no_stopped_body() {
        let stages = vec![vec![pred("x"), pred("y")], vec![pred("p")]];
        assert_eq!(channels(&stages, &[side("y")]), ["p"]);
        assert_eq!(channels(&stages, &[side("x")]), ["p"]);
        assert!(channels(&stages, &[]).is_empty(), "no stops seen");
        let one_stage = vec![vec![pred("x"), pred("y"), pred("p")]];
        assert!(channels(&one_stage, &[side("y")]).is_empty());
    }

    fn entry(effect: &str, before: f64, closure: (f64, f64)) -> RankEntry {
        RankEntry {
            fitted: true,
            moved: true,
            untouched: Some(UntouchedClosure {
                channels: vec!["p".into()],
                before,
                after: before * (1.0 - closure.0),
                closure: Interval {
                    value: closure.0,
                    ci_low: closure.1,
                    ci_high: 1.0,
                },
            }),
            ..RankEntry::named(effect)
        }
    }

    #[test]
    fn the_candidate_that_closes_the_most_of_a_real_gap_is_named() {
        let infos: Vec<&EffectInfo> = EFFECTS.iter().collect();
        // the stops beside a leak (evaluation seed 1005): the gas channel at 4.81 noise sd
        // (23 noise variances); the leak takes it to 1.01, the gain to 1.30
        let d = vec![
            entry("sensor_gain", 23.1, (0.969, 0.95)),
            entry("leak", 23.1, (0.999, 0.99)),
            entry("sensor_lag", 23.1, (0.66, 0.6)),
        ];
        assert_eq!(best(&d, &infos).map(|e| e.effect.as_str()), Some("leak"));
        // no gap on the untouched channels (the stops alone: 1.08 noise variances at most)
        let d = vec![entry("sensor_lag", 1.08, (0.9, 0.7))];
        assert!(best(&d, &infos).is_none());
        // a gap no candidate closes with confidence (the outside cause beside the stops)
        let d = vec![entry("sensor_gain", 4.4, (0.11, 0.05))];
        assert!(best(&d, &infos).is_none());
        // the best closes but its bound does not clear: nothing, not the runner-up
        let d = vec![
            entry("leak", 23.1, (0.9, 0.45)),
            entry("sensor_gain", 23.1, (0.8, 0.6)),
        ];
        assert!(best(&d, &infos).is_none());
        // an effect with travels is never named here
        let d = vec![entry("end_stops", 23.1, (0.99, 0.98))];
        assert!(best(&d, &infos).is_none());
    }

    #[test]
    fn stops_from_the_acceleration_carry_no_interval_and_no_simulated_closure() {
        let s = seen_step("end_stops", &[side("y")]);
        assert_eq!(s.effects, ["end_stops"]);
        assert_eq!(s.params.len(), 2);
        assert!(s.params.iter().all(|q| q.ci_low.is_nan()));
        assert!(s.cumulative.value.is_nan());
        assert!(s.simulation_gap_note.is_some());
    }
}
