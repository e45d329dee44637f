//! The query string of an endpoint: the model (a family member, or `@ID` for an engine
//! compiled from the page), its `n`, and parameter overrides, checked.

use stirling_dsl::{Closure, Model};

use super::engines;

/// The largest `n` the page computes (the limit keeps a request short).
pub const MAX_N: usize = 50;

/// A checked query: `model=cv2&n=2&Th=650&...`.
pub struct Query {
    pub model: String,
    pub n: Option<usize>,
    /// Overrides as `NAME=VALUE`, each value a finite number.
    pub sets: Vec<String>,
}

impl Query {
    /// Parse `q` (no percent-encoding is expected: names and numbers only).
    pub fn parse(q: &str) -> Result<Query, String> {
        let mut model = None;
        let mut n = None;
        let mut sets = Vec::new();
        for pair in q.split('&').filter(|s| !s.is_empty()) {
            let (k, v) = pair
                .split_once('=')
                .ok_or_else(|| format!("`{pair}` is not NAME=VALUE"))?;
            match k {
                "model" => model = Some(v.to_owned()),
                "n" => n = Some(parse_n(v)?),
                _ => sets.push(format!("{k}={}", finite(k, v)?)),
            }
        }
        let model = model.ok_or("the query has no `model=` (schmidt, cv1, cv2, nsection)")?;
        Ok(Query { model, n, sets })
    }

    /// The model and its validated parameters (unknown model or parameter, unphysical value:
    /// the library's message).
    pub fn load(&self) -> Result<(Box<dyn Model>, Vec<f64>), String> {
        let model = self.model()?;
        let p = stirling_models::params::load(model.as_ref(), None, &self.sets)
            .map_err(|e| e.to_string())?;
        Ok((model, p))
    }

    /// The model named: `@ID` an engine compiled from the page, else a family member (never
    /// a file: the page reads none).
    fn model(&self) -> Result<Box<dyn Model>, String> {
        if let Some(id) = self.model.strip_prefix('@') {
            let def = engines::find(id).ok_or_else(|| {
                format!(
                    "{GONE}: `@{id}` (the server keeps the last {} it compiled; compile it again)",
                    engines::KEPT
                )
            })?;
            return engines::model(&def, self.n.unwrap_or(1));
        }
        if stirling_models::files::is_file(&self.model) {
            return Err(format!(
                "`{}`: the page reads no file; send the declaration to /api/compile",
                self.model
            ));
        }
        stirling_models::build(&self.model, self.n, Closure::Full).map_err(|e| e.to_string())
    }
}

/// How the message of an engine the server no longer keeps begins (the page compiles again).
pub const GONE: &str = "no engine compiled under this id";

pub fn parse_n(v: &str) -> Result<usize, String> {
    match v.parse::<usize>() {
        Ok(n) if (1..=MAX_N).contains(&n) => Ok(n),
        _ => Err(format!(
            "n = `{v}`: the page takes a whole number from 1 to {MAX_N}"
        )),
    }
}

fn finite(k: &str, v: &str) -> Result<f64, String> {
    v.parse::<f64>()
        .ok()
        .filter(|x| x.is_finite())
        .ok_or_else(|| format!("`{k}` = `{v}` is not a finite number"))
}
