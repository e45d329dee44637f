//! The backward check of the explanation: an effect named at an earlier step that the last
//! step's joint fit no longer needs is not kept (docs/diagnosis.md, Method step 8, "An
//! earlier step not kept").
//!
//! Why: the steps are forward selection; each names what closes most of what is left at that
//! point, and an effect can stand in for one that is named later. The last step refits every
//! named effect jointly, so its intervals are the Wald test of each earlier effect given the
//! others: when every strength of an earlier effect has an interval covering its null, the
//! model with the later effects does not need it. Measured: beside end stops and a 5 %
//! position gain, a quadratic regenerator loss was named second (it made up part of the
//! stroke the gain hides) and the gain third; with the gain, the loss's `Rq` was 2.5e7
//! [-2.6e7, 7.6e7] on one record and 0 on the other. The check only removes names; it fits
//! nothing, and the cumulative closure stays the chain's (the dropped effect's share of it
//! is within its interval of zero).

use super::types::Step;
use crate::effects::EffectInfo;

/// Mark the steps before the last whose effects the last step's fit does not need: every
/// strength (a parameter with a null) of each, among the last step's estimates, has a 95 %
/// interval that covers its null. `infos`: the candidates. Steps named on the one-run pass
/// ([`super::partner`]) are not part of the chain and are left alone.
pub fn mark(steps: &mut [Step], infos: &[&EffectInfo]) {
    let Some(last) = steps.iter().rposition(|s| !s.one_run) else {
        return;
    };
    let params = steps[last].params.clone();
    for s in steps[..last].iter_mut().filter(|s| !s.one_run) {
        let strengths: Vec<_> = s
            .effects
            .iter()
            .filter_map(|n| infos.iter().find(|i| i.name == n))
            .flat_map(|i| i.params.iter().filter_map(|q| q.null.map(|z| (q.name, z))))
            .filter_map(|(name, null)| params.iter().find(|p| p.name == name).map(|p| (p, null)))
            .collect();
        let covered = !strengths.is_empty()
            && strengths
                .iter()
                .all(|(p, null)| p.ci_low <= *null && *null <= p.ci_high);
        if covered {
            let what: Vec<String> = strengths
                .iter()
                .map(|(p, _)| {
                    format!(
                        "{} {:.3e} [{:.3e}, {:.3e}]",
                        p.name, p.value, p.ci_low, p.ci_high
                    )
                })
                .collect();
            s.superseded = Some(super::types::Superseded {
                by_step: last + 1,
                reason: format!(
                    "not kept: fitted with step {}'s effects its strength's interval covers its null ({})",
                    last + 1,
                    what.join(", ")
                ),
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnose::types::{EffectEstimate, RankEntry};
    use crate::effects::effect;

    fn est(name: &str, value: f64, half: f64) -> EffectEstimate {
        EffectEstimate {
            name: name.into(),
            value,
            std_error: half / 1.96,
            ci_low: value - half,
            ci_high: value + half,
            unit: String::new(),
        }
    }

    fn step(name: &str, params: Vec<EffectEstimate>) -> Step {
        let mut s = Step::of_entry(&RankEntry::named(name));
        s.params = params;
        s
    }

    #[test]
    fn an_earlier_effect_whose_interval_covers_its_null_at_the_last_step_is_not_kept() {
        let infos =
            ["end_stops", "regen_quadratic", "sensor_gain", "leak"].map(|n| effect(n).unwrap());
        let last = vec![
            est("kc", 1.83e5, 3e3),
            est("Rq", 2.5e7, 5.1e7),
            est("gain_x", 0.044, 0.016),
            est("gain_y", 0.049, 0.004),
        ];
        let mut steps = vec![
            step("end_stops", vec![est("kc", 1.76e5, 3e3)]),
            step(
                "regen_quadratic",
                vec![est("kc", 1.76e5, 3e3), est("Rq", 1.9e7, 5e6)],
            ),
            step("sensor_gain", last.clone()),
        ];
        mark(&mut steps, &infos);
        assert!(steps[0].superseded.is_none(), "the stops stay");
        let s = steps[1].superseded.as_ref().expect("the loss is dropped");
        assert_eq!(s.by_step, 3);
        assert!(s.reason.contains("Rq"), "{}", s.reason);
        assert!(
            steps[2].superseded.is_none(),
            "the last step is never checked"
        );

        // a gain with one of its two strengths clear of zero is kept
        let mut steps = vec![
            step(
                "sensor_gain",
                vec![est("gain_x", 0.0, 0.01), est("gain_y", 0.05, 0.01)],
            ),
            step(
                "leak",
                vec![
                    est("gain_x", 0.0, 0.01),
                    est("gain_y", 0.05, 0.01),
                    est("Gleak", 2e-8, 1e-8),
                ],
            ),
        ];
        mark(&mut steps, &infos);
        assert!(steps[0].superseded.is_none());
    }
}
