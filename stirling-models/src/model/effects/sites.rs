//! The effects a model carries when it names them with `effect` items
//! ([`Model::effect_sites`]): one [`EffectInfo`] per effect kind it names, its parameters those
//! of its sites (`effect coulomb on piston;` gives `coulomb` with `Fc_piston`, `v_eps`), so the
//! diagnosis tests what the model declares, wherever it acts, under the names it chose.

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use stirling_dsl::Model;

use super::{effect, EffectInfo, EffectParam, EffectTarget, EFFECTS};

/// The effects of `model`: built from its `effect` items (none: an empty list), then the
/// sensor effects, which act on the records of any model. Built once per model name and kept
/// (`'static`, as the library's).
pub fn from_sites(model: &dyn Model) -> Vec<&'static EffectInfo> {
    static CACHE: OnceLock<Mutex<HashMap<String, Vec<&'static EffectInfo>>>> = OnceLock::new();
    let sites = model.effect_sites();
    if sites.is_empty() {
        return Vec::new();
    }
    let cache = CACHE.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    let key = format!("{}#{}", model.name(), model.params().len());
    let list = cache.entry(key).or_insert_with(|| build(model));
    let mut out = list.clone();
    out.extend(EFFECTS.iter().filter(|e| e.target == EffectTarget::Sensor));
    out
}

/// One leaked [`EffectInfo`] per effect kind among the sites, in order of first appearance.
fn build(model: &dyn Model) -> Vec<&'static EffectInfo> {
    let sites = model.effect_sites();
    let mut kinds: Vec<&'static str> = Vec::new();
    for s in sites {
        if !kinds.contains(&s.effect) {
            kinds.push(s.effect);
        }
    }
    let base: &'static str = model.name();
    kinds
        .into_iter()
        .map(|kind| {
            let at: Vec<&str> = sites
                .iter()
                .filter(|s| s.effect == kind)
                .map(|s| s.at)
                .collect();
            let params = params_of(model, kind);
            let lib = library(kind);
            let what = lib.map_or(kind, |e| e.summary);
            let info = EffectInfo {
                name: kind,
                summary: Box::leak(format!("{what} (at {})", at.join(", ")).into_boxed_str()),
                target: target(kind),
                params: Box::leak(params.into_boxed_slice()),
                applies_to: Box::leak(vec![base].into_boxed_slice()),
            };
            &*Box::leak(Box::new(info))
        })
        .collect()
}

/// The parameters of effect `kind` over all its sites: the strengths first (null 0), then the
/// shapes (no null; typical: the model's default), each once.
fn params_of(model: &dyn Model, kind: &str) -> Vec<EffectParam> {
    let sites: Vec<_> = model
        .effect_sites()
        .iter()
        .filter(|s| s.effect == kind)
        .collect();
    let mut out: Vec<EffectParam> = Vec::new();
    let info = |name: &str| model.param_index(name).map(|i| &model.params()[i]);
    for strength in [true, false] {
        for s in &sites {
            for (k, &name) in s.params.iter().enumerate() {
                if (k == 0) != strength || out.iter().any(|q| q.name == name) {
                    continue;
                }
                let typical = if strength {
                    typical_strength(kind, name)
                } else {
                    info(name).map_or(0.0, |q| q.default)
                };
                let null = strength.then_some(0.0);
                out.push(EffectParam {
                    name,
                    null,
                    typical,
                    unit: info(name).map_or(sensor_unit(kind), |q| q.unit),
                });
            }
        }
    }
    out
}

/// A clearly visible strength: the library's for a parameter of that name, else the
/// library's for the effect (its strength parameter's).
fn typical_strength(kind: &str, name: &str) -> f64 {
    let lib = library(kind);
    lib.and_then(|e| e.params.iter().find(|p| p.name == name))
        .or_else(|| lib.map(EffectInfo::strength))
        .map_or(1.0, |p| p.typical)
}

/// The library's effect of an `effect` kind (`quadratic` on a link is the library's
/// `regen_quadratic` on the regenerator's links; `lag` and `gain` on a sensor are the
/// library's `sensor_lag` and `sensor_gain` on that sensor alone).
fn library(kind: &str) -> Option<&'static EffectInfo> {
    effect(match kind {
        "quadratic" => "regen_quadratic",
        "lag" => "sensor_lag",
        "gain" => "sensor_gain",
        k => k,
    })
}

/// What an `effect` kind acts on: the sensors' readings (`lag`, `gain`: the rig applies
/// them, the diagnosis fits them) or the model.
fn target(kind: &str) -> EffectTarget {
    match kind {
        "lag" | "gain" => EffectTarget::Sensor,
        _ => EffectTarget::Model,
    }
}

/// The unit of a sensor effect's parameter (not a model parameter, so not declared).
fn sensor_unit(kind: &str) -> &'static str {
    match kind {
        "lag" => "s",
        _ => "-",
    }
}
