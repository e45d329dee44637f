//! The last check of a verdict that names effects: the model with them, run on its own over
//! the held-out block, must not be further from the record than the calibrated model.
//!
//! The steps name effects on the driven subsystems (stage 1 driven by the measured pressure,
//! stage 2 by the measured positions), where pointwise residuals are meaningful. A fit there
//! can close the driven gap with strengths that do not carry over to the running engine: on
//! the self-check's `sensor_gain` record (gains +5 % on both positions), fitted with the
//! mechanics stage's rows too, the gain closed 0.81 of the driven gap with `gain_x` at -4.6 %
//! and the fitted engine, run free, died out (simulated closure -388 [-892, -72]; the gain is
//! now estimated in the gas stage, `joint::effect_vars`). Such a verdict keeps its effects,
//! since the driven evidence stands, but says that its strengths do not describe the engine.

use super::sim_gap::FeatureError;
use super::types::{Diagnosis, Verdict};

/// Flag `d`'s verdict when it names effects and the simulated closure of the model with
/// them lies below zero with confidence; the reason says so with the numbers.
pub fn flag(d: &mut Diagnosis) {
    let closure = d.simulation_gap.as_ref().and_then(|g| g.closure.as_ref());
    flag_verdict(&mut d.verdict, closure);
}

/// [`flag`] on the verdict, given the simulated closure of the model with its effects.
fn flag_verdict(v: &mut Verdict, closure: Option<&FeatureError>) {
    if v.verdict != "effect" {
        return;
    }
    let Some(c) = closure else {
        return;
    };
    if !(c.ci_high < 0.0) {
        return;
    }
    v.free_run_worse = true;
    v.reason.push_str(&format!(
        "; but the model with them, run on its own over the held-out block, is further from the \
         record than the calibrated model (simulated closure {:.2} [{:.2}, {:.2}]): the fitted \
         strengths close the gap of the driven subsystems, not the running engine's; read them \
         with care",
        c.value, c.ci_low, c.ci_high
    ));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn verdict(kind: &str) -> Verdict {
        Verdict {
            verdict: kind.into(),
            effect: Some("sensor_gain".into()),
            effects: vec!["sensor_gain".into()],
            unexplained_remainder: false,
            free_run_worse: false,
            closure_fraction: Some(0.8),
            ci_low: Some(0.7),
            ci_high: Some(0.9),
            gap: 8.0,
            reason: "named".into(),
        }
    }

    fn closure(ci_high: f64) -> FeatureError {
        FeatureError {
            value: ci_high - 1.0,
            ci_low: ci_high - 2.0,
            ci_high,
        }
    }

    #[test]
    fn a_free_run_worse_with_confidence_flags_a_verdict_that_names_effects() {
        let mut v = verdict("effect");
        flag_verdict(&mut v, Some(&closure(-0.5)));
        assert!(v.free_run_worse);
        assert!(
            v.reason.starts_with("named; but the model with them"),
            "{}",
            v.reason
        );
        assert!(v.reason.contains("read them with care"));
    }

    #[test]
    fn an_interval_that_holds_zero_or_no_effect_named_leaves_the_verdict() {
        for (kind, c) in [
            ("effect", Some(closure(0.1))),
            ("effect", None),
            ("unexplained", Some(closure(-0.5))),
        ] {
            let mut v = verdict(kind);
            flag_verdict(&mut v, c.as_ref());
            assert!(!v.free_run_worse, "{kind} {c:?}");
            assert_eq!(v.reason, "named");
        }
    }
}
