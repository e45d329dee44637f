//! The candidate effects of a diagnosis and the nominal (augmented, at the nulls) model.

use stirling_dsl::{Closure, Model};

use super::DiagnoseError;
use crate::effects::{self, EffectInfo};

/// The candidate effects of a diagnosis.
pub(super) fn candidates(
    model: &dyn Model,
    names: &Option<Vec<String>>,
) -> Result<Vec<&'static EffectInfo>, DiagnoseError> {
    let base = model.name().trim_end_matches("_fx").to_string();
    // a model outside the library (a user's augmented engine) carries the effects it names
    // with `effect` items, or else those whose every parameter it declares; the sensor effects
    // act on the records of any model
    let pool = super::kinematic::candidate_pool(model, effects::carried(&base, Some(model)));
    let Some(names) = names else {
        return Ok(pool);
    };
    if let Some(name) = crate::fit::identify::first_duplicate(names) {
        return Err(DiagnoseError::DuplicateEffect { name });
    }
    let mut v = Vec::new();
    for n in names {
        if let Some(e) = pool.iter().find(|e| e.name == n) {
            v.push(*e);
            continue;
        }
        let e = effects::effect(n).ok_or_else(|| DiagnoseError::UnknownEffect {
            name: n.clone(),
            known: effects::EFFECTS
                .iter()
                .map(|e| e.name)
                .collect::<Vec<_>>()
                .join(", "),
        })?;
        return Err(DiagnoseError::NotApplicable {
            effect: n.clone(),
            model: base.clone(),
            applies: e.applies_to.join(", "),
        });
    }
    Ok(v)
}

/// The augmented model of a base model name, with its nominal parameters.
pub fn nominal_model(
    base: &str,
    n: Option<usize>,
) -> Result<(Box<dyn Model>, Vec<f64>), DiagnoseError> {
    let m = effects::augmented(base, n, Closure::Full)?;
    let p = effects::nominal_params(m.as_ref());
    Ok((m, p))
}
