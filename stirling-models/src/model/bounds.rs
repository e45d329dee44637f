//! Bounds of model parameters from a file (`stirling fit --bounds FILE`): TOML
//! `kd = [100.0, 2000.0]` or JSON `{"kd": [100.0, 2000.0]}`, each a declared parameter and a
//! finite range, lower below upper. They override the bounds the model declares
//! (`kd: 650.0 "N/m" in 100.0..2000.0`).

use std::path::Path;

use stirling_dsl::Model;

use super::params::ParamError;

/// `(name, lo, hi)` from `path`.
pub fn load_bounds(model: &dyn Model, path: &Path) -> Result<Vec<(String, f64, f64)>, ParamError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| ParamError::Read {
        path: shown.clone(),
        why: e.to_string(),
    })?;
    let parse_err = |why: String| ParamError::Parse {
        path: shown.clone(),
        why,
    };
    let entries: Vec<(String, serde_json::Value)> =
        if path.extension().is_some_and(|e| e == "toml") {
            let table: toml::Table = toml::from_str(&text).map_err(|e| parse_err(e.to_string()))?;
            let json = serde_json::to_value(table).map_err(|e| parse_err(e.to_string()))?;
            object(json)
        } else {
            let json: serde_json::Value =
                serde_json::from_str(&text).map_err(|e| parse_err(e.to_string()))?;
            object(json)
        }
        .ok_or_else(|| parse_err("expected a table of `name = [lo, hi]`".into()))?;
    let mut out = Vec::new();
    for (name, v) in entries {
        if model.param_index(&name).is_none() {
            let valid: Vec<&str> = model.params().iter().map(|p| p.name).collect();
            return Err(ParamError::Unknown {
                origin: shown.clone(),
                name,
                model: model.name().into(),
                valid: valid.join(", "),
            });
        }
        let pair = v
            .as_array()
            .filter(|a| a.len() == 2)
            .and_then(|a| Some((a[0].as_f64()?, a[1].as_f64()?)));
        match pair {
            Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo < hi => {
                out.push((name, lo, hi))
            }
            _ => {
                return Err(parse_err(format!(
                    "bounds of `{name}`: expected [lo, hi] with finite numbers lo < hi, found {v}"
                )))
            }
        }
    }
    Ok(out)
}

/// The entries of a JSON object, in file order for TOML's sorted keys alike.
fn object(v: serde_json::Value) -> Option<Vec<(String, serde_json::Value)>> {
    match v {
        serde_json::Value::Object(m) => Some(m.into_iter().collect()),
        _ => None,
    }
}
