//! The last check of a verdict that names effects: the model with them, run on its own over
//! the held-out block, must not be further from the record than the calibrated model.
//!
//! The steps name effects on the driven subsystems (stage 1 driven by the measured pressure,
//! stage 2 by the measured positions), where pointwise residuals are meaningful. A fit there
//! can close the driven gap with strengths that do not carry over to the running engine: on
//! the self-check's `sensor_gain` record (gains +5 % on both positions) the gain's fit closes
//! 0.81 of the driven gap with `gain_x` at -4.6 % (its interval excludes the truth: the
//! mechanics stage alone pulls it negative), and the fitted engine, run free, dies out
//! (simulated closure -388 [-892, -72]). Such a verdict keeps its effects, since the driven
//! evidence stands, but says that its strengths do not describe the engine.

use super::types::Diagnosis;

/// Flag `d`'s verdict when it names effects and the simulated closure of the model with
/// them lies below zero with confidence; the reason says so with the numbers.
pub fn flag(d: &mut Diagnosis) {
    if d.verdict.verdict != "effect" {
        return;
    }
    let Some(c) = d.simulation_gap.as_ref().and_then(|g| g.closure.as_ref()) else {
        return;
    };
    if !(c.ci_high < 0.0) {
        return;
    }
    d.verdict.free_run_worse = true;
    d.verdict.reason.push_str(&format!(
        "; but the model with them, run on its own over the held-out block, is further from the \
         record than the calibrated model (simulated closure {:.2} [{:.2}, {:.2}]): the fitted \
         strengths close the gap of the driven subsystems, not the running engine's; read them \
         with care",
        c.value, c.ci_low, c.ci_high
    ));
}
