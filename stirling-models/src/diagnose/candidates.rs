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

#[cfg(test)]
mod tests {
    use super::*;

    /// The leak's typical strength of a kinematic engine declared in `text` with the
    /// engine's own `Gleak` default replaced by `gleak`, loaded from a file of its own.
    fn leak_typical(text: &str, gleak: &str, tag: &str) -> f64 {
        let dir = std::env::temp_dir().join(format!("stirling-pool-{}-{tag}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("gamma.stirling");
        std::fs::write(
            &path,
            text.replace("Gleak: 4.0e-10", &format!("Gleak: {gleak}")),
        )
        .unwrap();
        let (m, _) = nominal_model(path.to_str().unwrap(), None).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        let pool = candidates(m.as_ref(), &None).unwrap();
        let leak = pool
            .iter()
            .find(|e| e.name == "leak")
            .expect("the file's leak");
        leak.params[0].typical
    }

    #[test]
    fn two_engines_of_one_name_get_their_own_typical_strengths() {
        // the same model name, other defaults: a process that diagnoses both (the page, the
        // Python module) must not hand the second the first one's candidates
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../examples/engines/gamma_ltd.stirling"
        );
        let text = std::fs::read_to_string(path).unwrap();
        assert!(
            text.contains("Gleak: 4.0e-10"),
            "the example's default moved"
        );
        assert_eq!(leak_typical(&text, "4.0e-10", "a"), 4.0e-10);
        assert_eq!(leak_typical(&text, "9.0e-10", "b"), 9.0e-10);
        assert_eq!(leak_typical(&text, "4.0e-10", "c"), 4.0e-10);
    }
}
