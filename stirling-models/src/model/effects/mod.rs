//! Effects the nominal models leave out (docs/physics.md section 9), as model augmentations
//! declared through the DSL (`models.rs`), and the registry that names them.
//!
//! Each model effect is a set of extra parameters of an augmented family member
//! ([`Cv1Fx`](crate::model::effects::Cv1Fx), [`NSectionFx`](crate::model::effects::NSectionFx))
//! whose null values make it absent; the nominal model is the augmented model at the nulls. Sensor
//! effects (`sensor_lag`, `sensor_gain`) act on the measured outputs, not on the model (see
//! [`crate::rig`]).
//!
//! The effects that need walls with a temperature state or the orifice law (regenerator matrix heat
//! capacity, a heater head with finite input, the orifice leak) are declared on a third augmented
//! member, [`NSectionExtFx`](crate::model::effects::NSectionExtFx) (base name `nsection_ext`), so
//! that the nominal models of `cv1` and `nsection` and their default candidate lists stay as they
//! are. Not expressible yet: the closed bounce space as a control volume with its own heat port as
//! an effect, and the end-stop contact damper `-cc v` (needs a step function of the position).

mod models;
mod sites;

pub(crate) use models::nsection_fx_engine;
pub use models::{
    Cv1Fx, Cv1FxParams, NSectionExtFx, NSectionExtFxParams, NSectionFx, NSectionFxParams,
};

use stirling_dsl::{Closure, Model};

/// Whether an effect changes the model or only the measured outputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum EffectTarget {
    Model,
    Sensor,
}

/// One parameter of an effect.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EffectParam {
    pub name: &'static str,
    /// The value at which the effect is absent (`None`: a shape parameter with no null,
    /// e.g. the travel to an end stop; it keeps its default).
    pub null: Option<f64>,
    /// A clearly visible strength on the default engine (for the rig and the self-checks).
    pub typical: f64,
    pub unit: &'static str,
}

/// An effect: its name, what it does, its parameters (the first is its strength).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct EffectInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub target: EffectTarget,
    pub params: &'static [EffectParam],
    /// Base models whose augmented member carries it (all, for sensor effects).
    pub applies_to: &'static [&'static str],
}

impl EffectInfo {
    /// The strength parameter (`NAME=VALUE` on the rig sets it).
    pub fn strength(&self) -> &'static EffectParam {
        &self.params[0]
    }
}

const fn ep(
    name: &'static str,
    null: Option<f64>,
    typical: f64,
    unit: &'static str,
) -> EffectParam {
    EffectParam {
        name,
        null,
        typical,
        unit,
    }
}

/// Typical inverse matrix capacity: `1/km` = 0.5 J/K (the default engine's steel-mesh matrix,
/// about 0.1 kg, is about 50 J/K: `km` = 0.02 K/J).
const KM_TYPICAL: f64 = 2.0;
/// Typical inverse heater-head capacity: `1/kh` = 25 J/K (a light head; a 0.5 kg steel head
/// is about 250 J/K, `kh` = 4e-3 K/J).
const KH_TYPICAL: f64 = 0.04;
/// Typical orifice coefficient: `Co = Cd A0 sqrt(2 rho)` with `Cd` 0.6, a 1.2 mm hole and air
/// at the charge (about 1e-6 kg/(s Pa^0.5), 5e-5 kg/s at 3 kPa, like `leak` at 2e-8).
const CO_TYPICAL: f64 = 1.0e-6;

/// The effect library. The effects that need wall states or the orifice law
/// (`matrix_capacity`, `heater_input`, `orifice_leak`) apply to `nsection_ext` only, the
/// augmented member [`NSectionExtFx`]: they add `n + 1` wall states, so they stay out of the
/// nominal models (and the default candidates) of `cv1` and `nsection`.
pub const EFFECTS: &[EffectInfo] = &[
    EffectInfo {
        name: "leak",
        summary: "seal leakage cold space -> bounce space, mdot = Gleak (Pc - Pb)",
        target: EffectTarget::Model,
        params: &[ep("Gleak", Some(0.0), 2.0e-8, "kg/(s Pa)")],
        applies_to: &["cv1", "nsection", "nsection_ext"],
    },
    EffectInfo {
        name: "coulomb",
        summary: "Coulomb friction on both bodies, -Fc tanh(v / v_eps)",
        target: EffectTarget::Model,
        params: &[
            ep("Fcd", Some(0.0), 0.3, "N"),
            ep("Fcp", Some(0.0), 1.0, "N"),
            ep("v_eps", None, 1.0e-3, "m/s"),
        ],
        applies_to: &["cv1", "nsection", "nsection_ext"],
    },
    EffectInfo {
        name: "regen_quadratic",
        summary: "quadratic (turbulent) regenerator friction, dP = Rf mdot + Rq mdot |mdot|",
        target: EffectTarget::Model,
        params: &[ep("Rq", Some(0.0), 1.0e9, "Pa s^2/kg^2")],
        applies_to: &["nsection", "nsection_ext"],
    },
    EffectInfo {
        name: "end_stops",
        summary: "end stops, -kc relu(|q| - q_max) sign(q) on both bodies",
        target: EffectTarget::Model,
        params: &[
            ep("kc", Some(0.0), 2.0e5, "N/m"),
            ep("xmax", None, 0.01, "m"),
            ep("ymax", None, 0.01, "m"),
        ],
        applies_to: &["cv1", "nsection", "nsection_ext"],
    },
    EffectInfo {
        name: "matrix_capacity",
        summary: "regenerator matrix of finite heat capacity 1/km: C_j Tw_j' = hA (T_j - Tw_j) + axial conduction Gm",
        target: EffectTarget::Model,
        params: &[ep("km", Some(0.0), KM_TYPICAL, "K/J"), ep("Gm", None, 0.03, "W/K")],
        applies_to: &["nsection_ext"],
    },
    EffectInfo {
        name: "heater_input",
        summary: "heater head of finite heat capacity 1/kh fed by Gloss (Th - Tk), losing Gloss (T_head - Tk) to the cooler",
        target: EffectTarget::Model,
        params: &[ep("kh", Some(0.0), KH_TYPICAL, "K/J"), ep("Gloss", None, 0.5, "W/K")],
        applies_to: &["nsection_ext"],
    },
    EffectInfo {
        name: "orifice_leak",
        summary: "square-root seal leak cold space -> bounce space, mdot = Co dP / (dP^2 + dP0^2)^(1/4)",
        target: EffectTarget::Model,
        params: &[ep("Co", Some(0.0), CO_TYPICAL, "kg/(s Pa^0.5)"), ep("dP0", None, 50.0, "Pa")],
        applies_to: &["nsection_ext"],
    },
    EffectInfo {
        name: "sensor_lag",
        summary: "first-order lag of the pressure transducers, time constant tau_p",
        target: EffectTarget::Sensor,
        params: &[ep("tau_p", Some(0.0), 2.0e-3, "s")],
        applies_to: &["cv1", "nsection", "nsection_ext"],
    },
    EffectInfo {
        name: "sensor_gain",
        summary: "position-sensor gain errors, x_meas = (1 + gain_x) x, y_meas = (1 + gain_y) y",
        target: EffectTarget::Sensor,
        params: &[
            ep("gain_x", Some(0.0), 0.05, "-"),
            ep("gain_y", Some(0.0), 0.05, "-"),
        ],
        applies_to: &["cv1", "nsection", "nsection_ext"],
    },
];

/// Why an effect request cannot be served.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum EffectError {
    #[error("unknown effect or effect parameter `{0}`: expected one of {1}")]
    Unknown(String, String),
    #[error("effect `{effect}` does not apply to model `{model}` (it applies to {applies})")]
    NotApplicable {
        effect: String,
        model: String,
        applies: String,
    },
    #[error("model `{0}` has no augmented member: effects are declared for cv1, nsection and nsection_ext (aliases order5, order7, order8), and for a registered model that names one")]
    NoAugmented(String),
    #[error("effect parameter `{name}` = {value} is not physical: it must be {range}")]
    OutOfRange {
        name: String,
        value: f64,
        range: &'static str,
    },
    #[error("bad effect setting `{0}`: expected NAME=VALUE with a finite number, e.g. leak=2e-8 or Gleak=2e-8")]
    BadSetting(String),
    #[error("{0}")]
    Model(String),
}

/// The effect by name.
pub fn effect(name: &str) -> Option<&'static EffectInfo> {
    EFFECTS.iter().find(|e| e.name == name)
}

/// The effect that owns a parameter.
pub fn effect_of_param(param: &str) -> Option<(&'static EffectInfo, &'static EffectParam)> {
    EFFECTS
        .iter()
        .find_map(|e| e.params.iter().find(|p| p.name == param).map(|p| (e, p)))
}

/// The effects that apply to a base model.
pub fn effects_for(base: &str) -> Vec<&'static EffectInfo> {
    let base = canonical(base).map(|(b, _)| b).unwrap_or(base);
    EFFECTS
        .iter()
        .filter(|e| e.applies_to.contains(&base))
        .collect()
}

/// Whether effect `e` applies to `base`: the library's list for a library base; for any other
/// model, a sensor effect always and a model effect when `model` (its augmented member)
/// declares every parameter of it.
pub fn applies(e: &EffectInfo, base: &str, model: Option<&dyn Model>) -> bool {
    match canonical(base) {
        Some((b, _)) => e.applies_to.contains(&b),
        None => {
            e.target == EffectTarget::Sensor
                || model.is_some_and(|m| e.params.iter().all(|q| m.param_index(q.name).is_some()))
        }
    }
}

/// The effects `base` carries, `model` its augmented member: the library's list for a library
/// base; for any other model, those it names with `effect` items (one per effect, over all its
/// sites, under its parameter names) and the sensor effects, or, for a model without `effect`
/// items, the library's effects whose every parameter it declares ([`applies`]).
pub fn carried(base: &str, model: Option<&dyn Model>) -> Vec<&'static EffectInfo> {
    if let (None, Some(m)) = (canonical(base), model) {
        let named = sites::from_sites(m);
        if !named.is_empty() {
            return named;
        }
    }
    EFFECTS.iter().filter(|e| applies(e, base, model)).collect()
}

/// Whether `base` is one of the library's base models (or an alias): its effects are the
/// library's list; any other model carries the effects whose parameters it declares.
pub fn in_library(base: &str) -> bool {
    canonical(base).is_some()
}

/// Canonical base name and the `n` an alias fixes.
fn canonical(name: &str) -> Option<(&'static str, Option<usize>)> {
    match name {
        "cv1" | "order5" | "cv1_fx" => Some(("cv1", None)),
        "nsection" | "nsection_fx" => Some(("nsection", None)),
        "nsection_ext" | "nsection_ext_fx" => Some(("nsection_ext", None)),
        "order7" => Some(("nsection", Some(1))),
        "order8" => Some(("nsection", Some(2))),
        _ => None,
    }
}

/// The augmented model of a base model (`cv1` -> [`Cv1Fx`], `nsection` -> [`NSectionFx`],
/// `nsection_ext` -> [`NSectionExtFx`], `n` checked like `nsection`'s).
pub fn augmented(
    base: &str,
    n: Option<usize>,
    closure: Closure,
) -> Result<Box<dyn Model>, EffectError> {
    if crate::files::is_file(base) {
        // an engine file declares its effects itself: it is its own augmented member
        return crate::registry::build(base, n, closure)
            .map_err(|e| EffectError::Model(e.to_string()));
    }
    if let Some(u) = crate::model::user_models::find(base) {
        // a model registered without an augmented member carries no model effect
        let build = u.augmented.unwrap_or(u.build);
        return build(n.unwrap_or(1), closure).map_err(|e| EffectError::Model(e.to_string()));
    }
    let (b, fixed) = canonical(base).ok_or_else(|| EffectError::NoAugmented(base.to_string()))?;
    // reuse the registry's checks of n and aliases
    let family = if b == "nsection_ext" {
        "nsection"
    } else {
        base
    };
    crate::registry::build(family, n, closure).map_err(|e| EffectError::Model(e.to_string()))?;
    let n = n.or(fixed).unwrap_or(1);
    let model_err = |e: stirling_dsl::ModelError| EffectError::Model(e.to_string());
    Ok(match b {
        "cv1" => Box::new(Cv1Fx::new(1, closure).map_err(model_err)?),
        "nsection_ext" => Box::new(NSectionExtFx::new(n, closure).map_err(model_err)?),
        _ => Box::new(NSectionFx::new(n, closure).map_err(model_err)?),
    })
}

/// Reject an effect parameter outside its physical range: strengths are non-negative,
/// smoothing widths, end-stop travels and the walls' loss conductances positive (they make the
/// rest state unique), sensor gains above -1 (a gain of -1 would
/// read zero for every position).
pub fn check_range(name: &str, v: f64) -> Result<(), EffectError> {
    let (ok, range) = match name {
        "v_eps" | "xmax" | "ymax" | "Gm" | "Gloss" | "dP0" => (v > 0.0, "> 0"),
        n if n.starts_with("Gh_") || n.starts_with("Gm_") => (v > 0.0, "> 0"),
        n if n.starts_with("gain_") => (v > -0.5 && v < 0.5, "between -0.5 and 0.5"),
        _ => (v >= 0.0, ">= 0"),
    };
    if ok {
        Ok(())
    } else {
        Err(EffectError::OutOfRange {
            name: name.into(),
            value: v,
            range,
        })
    }
}

/// Parameters of the augmented model with every effect at its null (the nominal model).
pub fn nominal_params(model: &dyn Model) -> Vec<f64> {
    let mut p = model.default_params();
    // an engine outside the library that names its effects is nulled at those alone: a
    // parameter of its own under a library effect's name is its own (the gamma LTD's
    // piston leak `Gleak`, 4e-10, is the library `leak`'s strength by name)
    let named = sites::from_sites(model);
    let library: &[EffectInfo] = if named.is_empty() || canonical(model.name()).is_some() {
        EFFECTS
    } else {
        &[]
    };
    for e in library.iter().chain(named) {
        for q in e.params {
            if let (Some(null), Some(i)) = (q.null, model.param_index(q.name)) {
                p[i] = null;
            }
        }
    }
    p
}

/// Effect settings: model parameters set on the augmented model and sensor parameters.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EffectSettings {
    /// `(parameter, value)` of model effects, in the order given.
    pub model: Vec<(String, f64)>,
    /// `(parameter, value)` of sensor effects.
    pub sensor: Vec<(String, f64)>,
}

impl EffectSettings {
    /// Parse `NAME=VALUE` settings: `NAME` is an effect (sets its strength parameter) or an
    /// effect parameter; checks that the effect applies to `base`.
    pub fn parse(base: &str, settings: &[String]) -> Result<Self, EffectError> {
        Self::parse_for(base, None, settings)
    }

    /// [`EffectSettings::parse`] for the augmented member `model` of `base`: a base outside
    /// the library (a registered user model) carries the effects whose parameters `model`
    /// declares ([`applies`]).
    pub fn parse_for(
        base: &str,
        model: Option<&dyn Model>,
        settings: &[String],
    ) -> Result<Self, EffectError> {
        let mut out = EffectSettings::default();
        let pool = carried(base, model);
        for s in settings {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| EffectError::BadSetting(s.clone()))?;
            let (k, v) = (k.trim(), v.trim());
            let v: f64 = v
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| EffectError::BadSetting(s.clone()))?;
            let in_pool = pool.iter().find_map(|e| {
                if e.name == k {
                    return Some((*e, e.strength()));
                }
                e.params.iter().find(|p| p.name == k).map(|p| (*e, p))
            });
            let (e, p) = match in_pool.or_else(|| effect(k).map(|e| (e, e.strength()))) {
                Some(found) => found,
                None => effect_of_param(k).ok_or_else(|| {
                    let names: Vec<String> = EFFECTS
                        .iter()
                        .flat_map(|e| {
                            std::iter::once(e.name).chain(e.params.iter().map(|p| p.name))
                        })
                        .map(String::from)
                        .collect();
                    EffectError::Unknown(k.to_string(), names.join(", "))
                })?,
            };
            if !pool.iter().any(|x| std::ptr::eq(*x, e)) {
                return Err(EffectError::NotApplicable {
                    effect: e.name.into(),
                    model: base.into(),
                    applies: e.applies_to.join(", "),
                });
            }
            check_range(p.name, v)?;
            let list = if e.target == EffectTarget::Model {
                &mut out.model
            } else {
                &mut out.sensor
            };
            list.retain(|(n, _)| n != p.name);
            list.push((p.name.to_string(), v));
        }
        Ok(out)
    }

    /// A sensor parameter's value when set.
    pub fn sensor_set(&self, name: &str) -> Option<f64> {
        self.sensor.iter().find(|(n, _)| n == name).map(|(_, v)| *v)
    }

    /// A sensor parameter's value (its null when not set).
    pub fn sensor_value(&self, name: &str) -> f64 {
        self.sensor_set(name).unwrap_or_else(|| {
            effect_of_param(name)
                .and_then(|(_, p)| p.null)
                .unwrap_or(0.0)
        })
    }

    /// Apply the model settings to a parameter vector of the augmented model.
    pub fn apply(&self, model: &dyn Model, p: &mut [f64]) -> Result<(), EffectError> {
        for (k, v) in &self.model {
            let i = model
                .param_index(k)
                .ok_or_else(|| EffectError::NotApplicable {
                    effect: k.clone(),
                    model: model.name().into(),
                    applies: String::new(),
                })?;
            p[i] = *v;
        }
        Ok(())
    }

    /// Names of the effects that are switched on (a strength away from its null).
    pub fn active(&self) -> Vec<&'static str> {
        let mut out: Vec<&'static str> = Vec::new();
        for (k, v) in self.model.iter().chain(&self.sensor) {
            if let Some((e, p)) = effect_of_param(k) {
                if p.null.is_some_and(|n| n != *v) && !out.contains(&e.name) {
                    out.push(e.name);
                }
            }
        }
        out
    }
}
