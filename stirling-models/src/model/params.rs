//! Parameter sets: the embedded defaults, parameter files (TOML or JSON, every
//! parameter by name), `name=value` overrides, and validation of physical ranges.

use std::path::Path;

use stirling_dsl::Model;

/// Why a parameter set is rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ParamError {
    #[error("cannot read parameter file {path}: {why}")]
    Read { path: String, why: String },
    #[error("parameter file {path}: {why}")]
    Parse { path: String, why: String },
    #[error("{origin}: unknown parameter `{name}` for model `{model}`; valid parameters: {valid}")]
    Unknown {
        origin: String,
        name: String,
        model: String,
        valid: String,
    },
    #[error("{origin}: parameter `{name}` must be a number, found {found}")]
    NotANumber {
        origin: String,
        name: String,
        found: String,
    },
    #[error("--set `{0}`: expected name=value, e.g. --set Th=650")]
    BadOverride(String),
    #[error("parameter `{name}` = {} is not physical: {why}", show(*.value))]
    Unphysical {
        name: String,
        value: f64,
        why: String,
    },
}

/// A value as a user reads it: plain in the engine's range, in powers of ten beyond it.
fn show(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The defaults, then the file (if any), then the overrides, then validation.
pub fn load(
    model: &dyn Model,
    file: Option<&Path>,
    sets: &[String],
) -> Result<Vec<f64>, ParamError> {
    let mut p = model.default_params();
    if let Some(path) = file {
        apply_file(model, path, &mut p)?;
    }
    for s in sets {
        apply_override(model, s, &mut p)?;
    }
    validate(model, &p)?;
    Ok(p)
}

fn unknown(model: &dyn Model, origin: &str, name: &str) -> ParamError {
    let valid: Vec<&str> = model.params().iter().map(|p| p.name).collect();
    ParamError::Unknown {
        origin: origin.into(),
        name: name.into(),
        model: model.name().into(),
        valid: valid.join(", "),
    }
}

/// Apply a TOML (`.toml`) or JSON (anything else) file of `name = value` pairs.
pub fn apply_file(model: &dyn Model, path: &Path, p: &mut [f64]) -> Result<(), ParamError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| ParamError::Read {
        path: shown.clone(),
        why: e.to_string(),
    })?;
    let toml_ext = path.extension().is_some_and(|e| e == "toml");
    let pairs = if toml_ext {
        toml_pairs(&text)
    } else {
        json_pairs(&text)
    }
    .map_err(|why| ParamError::Parse {
        path: shown.clone(),
        why: format!("{why}\n{}", format_note(toml_ext, &text)),
    })?;
    for (name, value) in pairs {
        let k = model
            .param_index(&name)
            .ok_or_else(|| unknown(model, &shown, &name))?;
        p[k] = value.map_err(|found| ParamError::NotANumber {
            origin: shown.clone(),
            name: name.clone(),
            found,
        })?;
    }
    Ok(())
}

/// A value as a finite number, else what was found.
type Number = Result<f64, String>;

fn finite(v: f64) -> Number {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{v} (not a finite number)"))
    }
}

/// `name = value` pairs of a TOML table (NaN and infinities reported as such).
fn toml_pairs(text: &str) -> Result<Vec<(String, Number)>, String> {
    let table: toml::Table = toml::from_str(text).map_err(|e| e.to_string())?;
    Ok(table
        .into_iter()
        .map(|(k, v)| {
            let n = match &v {
                toml::Value::Float(f) => finite(*f),
                toml::Value::Integer(i) => Ok(*i as f64),
                other => Err(format!("{other} ({})", other.type_str())),
            };
            (k, n)
        })
        .collect())
}

/// `name: value` pairs of a JSON object.
fn json_pairs(text: &str) -> Result<Vec<(String, Number)>, String> {
    let map: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(text).map_err(|e| e.to_string())?;
    Ok(map
        .into_iter()
        .map(|(k, v)| {
            let n = v.as_f64().ok_or_else(|| v.to_string());
            (k, n)
        })
        .collect())
}

/// Which format a parameter file was read as, and a hint when its text looks like the other.
fn format_note(toml_ext: bool, text: &str) -> String {
    let looks_json = text.trim_start().starts_with('{');
    match (toml_ext, looks_json) {
        (true, true) => "read as TOML (the file name ends in .toml), but the text looks like JSON: rename it to .json".into(),
        (true, false) => "read as TOML (the file name ends in .toml)".into(),
        (false, false) => "read as JSON (the file name does not end in .toml); if it is TOML, rename it to .toml".into(),
        (false, true) => "read as JSON (the file name does not end in .toml)".into(),
    }
}

/// Apply one `name=value` override.
pub fn apply_override(model: &dyn Model, s: &str, p: &mut [f64]) -> Result<(), ParamError> {
    let (name, value) = s
        .split_once('=')
        .ok_or_else(|| ParamError::BadOverride(s.to_string()))?;
    let (name, value) = (name.trim(), value.trim());
    let origin = format!("--set {s}");
    let k = model
        .param_index(name)
        .ok_or_else(|| unknown(model, &origin, name))?;
    p[k] = value.parse().map_err(|_| ParamError::NotANumber {
        origin,
        name: name.into(),
        found: value.into(),
    })?;
    Ok(())
}

/// Physical ranges: finite values; positive masses, volumes, areas, temperatures,
/// pressures, gas constants; `Th > Tk`, `Ar < A`, `gamma > 1`; non-negative springs,
/// dampers, heat-transfer coefficients and resistances (angles, unit `rad`, of any sign).
pub fn validate(model: &dyn Model, p: &[f64]) -> Result<(), ParamError> {
    let get = |n: &str| model.param_index(n).map(|k| p[k]);
    for (info, &v) in model.params().iter().zip(p) {
        let bad = |why: &str| {
            Err(ParamError::Unphysical {
                name: info.name.into(),
                value: v,
                why: why.into(),
            })
        };
        if !v.is_finite() {
            return bad("must be finite");
        }
        let must_be_positive = matches!(
            info.unit,
            "kg" | "m^2" | "m^3" | "K" | "Pa" | "J/(kg K)" | "kg/s" | "Pa s/kg" | "W/(m^2 K)"
        );
        if must_be_positive && v <= 0.0 {
            return bad(&format!("must be positive (unit {})", info.unit));
        }
        // an angle (a crank's phase, docs/physics.md section 12) may have either sign
        let signed = matches!(info.unit, "-" | "rad");
        if !must_be_positive && !signed && v < 0.0 && info.name != "Vb0" {
            return bad(&format!("must not be negative (unit {})", info.unit));
        }
        if let Some(why) = out_of_scale(v, info.default) {
            return bad(&why);
        }
    }
    if let Some(g) = get("gamma") {
        if g <= 1.0 {
            return Err(ParamError::Unphysical {
                name: "gamma".into(),
                value: g,
                why: "the heat-capacity ratio must exceed 1".into(),
            });
        }
    }
    if let (Some(th), Some(tk)) = (get("Th"), get("Tk")) {
        if th <= tk {
            return Err(ParamError::Unphysical {
                name: "Th".into(),
                value: th,
                why: format!("the hot wall must be hotter than the cold wall (Tk = {tk})"),
            });
        }
    }
    if let (Some(a), Some(ar)) = (get("A"), get("Ar")) {
        if ar >= a {
            return Err(ParamError::Unphysical {
                name: "Ar".into(),
                value: ar,
                why: format!("the rod must be thinner than the cylinder (A = {a})"),
            });
        }
    }
    Ok(())
}

/// How far a parameter may move from its declared default, as a factor either way. Beyond
/// it the model's time scales span more than double precision resolves: `kd` = 1e30 N/m puts
/// a pole at 3.5e15 rad/s beside the engine's 95 rad/s, the Jacobian's entries then span
/// 1e29 while eigenvalues are resolved to `1e-16` of the largest, and a simulation's step
/// size collapses. No engine this model describes lies there; a value so far off is a typo or
/// a unit slip.
pub const MAX_SCALE: f64 = 1.0e8;

/// Why `v` lies beyond [`MAX_SCALE`] of its `default` (`None`: within it, or a default of 0,
/// which sets no scale).
fn out_of_scale(v: f64, default: f64) -> Option<String> {
    if default == 0.0 || v == 0.0 {
        return None;
    }
    let ratio = (v / default).abs();
    (!(1.0 / MAX_SCALE..=MAX_SCALE).contains(&ratio)).then(|| {
        format!(
            "it is {ratio:.2e} times its default {default}, beyond the factor {MAX_SCALE:.0e} either way within which the model's time scales stay resolvable in double precision: check the value and its unit"
        )
    })
}

/// The parameter vector `p` of `model` as `(name, value)` pairs, in declaration order.
pub fn named(model: &dyn Model, p: &[f64]) -> Vec<(String, f64)> {
    model
        .params()
        .iter()
        .zip(p)
        .map(|(i, v)| (i.name.to_string(), *v))
        .collect()
}
