//! The family by name: `schmidt`, `cv1`, `cv2`, `nsection`, and the seed's order aliases.

use stirling_dsl::{Closure, Model};

use crate::family::{Cv1, Cv2, NSection, Schmidt};

/// A family member as the command line names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelEntry {
    pub name: &'static str,
    pub aliases: &'static [&'static str],
    pub summary: &'static str,
}

/// The family with its aliases (`order4`..`order8` as the seed counts orders, i.e. frozen).
pub const FAMILY: &[ModelEntry] = &[
    ModelEntry { name: "schmidt", aliases: &["order4"], summary: "isothermal spaces at one algebraic pressure (4 states)" },
    ModelEntry { name: "cv1", aliases: &["order5"], summary: "one gas control volume, three heat ports (5 states)" },
    ModelEntry { name: "cv2", aliases: &["order6"], summary: "two CVs joined by the regenerator resistance (6 frozen / 8 full)" },
    ModelEntry {
        name: "nsection",
        aliases: &["order7", "order8"],
        summary: "hot space, n regenerator sections, cold space (n+6 frozen / 2n+8 full); order7 = n 1, order8 = n 2",
    },
];

/// Why a model request cannot be served.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RegistryError {
    #[error(
        "unknown model `{0}`: expected one of schmidt, cv1, cv2, nsection (aliases order4..order8){more}",
        more = registered_list()
    )]
    UnknownModel(String),
    #[error("model `{model}`: {why}")]
    User { model: String, why: String },
    /// An engine file that does not load or build (its messages at `path:line:column`).
    #[error("{0}")]
    File(String),
    #[error("model `{model}` has no regenerator sections: --n {n} does not apply (omit --n)")]
    NotAnArray { model: String, n: usize },
    #[error("--n must be at least 1, found {0}")]
    ZeroSections(usize),
    #[error("alias `{alias}` fixes n = {fixed}; --n {n} contradicts it")]
    AliasFixesN {
        alias: String,
        fixed: usize,
        n: usize,
    },
}

/// Build a family member, a registered model or the model of an engine file (a name ending
/// in `.stirling`, [`crate::files`]); `n` is `None` when not given (default 1 section for
/// `nsection` and a file's arrays).
pub fn build(
    name: &str,
    n: Option<usize>,
    closure: Closure,
) -> Result<Box<dyn Model>, RegistryError> {
    if crate::files::is_file(name) {
        return file_model(name, n, closure);
    }
    let (canonical, fixed_n) = match name {
        "order4" => ("schmidt", None),
        "order5" => ("cv1", None),
        "order6" => ("cv2", None),
        "order7" => ("nsection", Some(1)),
        "order8" => ("nsection", Some(2)),
        other => (other, None),
    };
    if let (Some(f), Some(n)) = (fixed_n, n) {
        if f != n {
            return Err(RegistryError::AliasFixesN {
                alias: name.to_string(),
                fixed: f,
                n,
            });
        }
    }
    if n == Some(0) {
        return Err(RegistryError::ZeroSections(0));
    }
    let scalar = |m: &str| match n {
        Some(k) if k != 1 => Err(RegistryError::NotAnArray {
            model: m.to_string(),
            n: k,
        }),
        _ => Ok(()),
    };
    let boxed: Box<dyn Model> = match canonical {
        "schmidt" => {
            scalar("schmidt")?;
            Box::new(Schmidt::new(1, closure).expect("n = 1 is valid"))
        }
        "cv1" => {
            scalar("cv1")?;
            Box::new(Cv1::new(1, closure).expect("n = 1 is valid"))
        }
        "cv2" => {
            scalar("cv2")?;
            Box::new(Cv2::new(1, closure).expect("n = 1 is valid"))
        }
        "nsection" => {
            let n = n.or(fixed_n).unwrap_or(1);
            Box::new(NSection::new(n, closure).map_err(|_| RegistryError::ZeroSections(n))?)
        }
        _ => return user_model(name, n, closure),
    };
    Ok(boxed)
}

/// The model of the engine file `name` at `n` (1 when not given).
fn file_model(
    name: &str,
    n: Option<usize>,
    closure: Closure,
) -> Result<Box<dyn Model>, RegistryError> {
    if n == Some(0) {
        return Err(RegistryError::ZeroSections(0));
    }
    let path = std::path::Path::new(name);
    crate::files::build(path, n.unwrap_or(1), closure)
        .map_err(|e| RegistryError::File(e.to_string()))
}

/// A registered user model ([`crate::model::user_models`]).
fn user_model(
    name: &str,
    n: Option<usize>,
    closure: Closure,
) -> Result<Box<dyn Model>, RegistryError> {
    let Some(u) = crate::model::user_models::find(name) else {
        return Err(RegistryError::UnknownModel(name.to_string()));
    };
    if let (false, Some(k)) = (u.has_array, n) {
        if k != 1 {
            return Err(RegistryError::NotAnArray {
                model: name.to_string(),
                n: k,
            });
        }
    }
    (u.build)(n.unwrap_or(1), closure).map_err(|e| RegistryError::User {
        model: name.to_string(),
        why: e.to_string(),
    })
}

/// `, or a registered model: a, b` (empty when none is registered).
fn registered_list() -> String {
    let names: Vec<&str> = crate::model::user_models::registered()
        .iter()
        .map(|u| u.name)
        .collect();
    if names.is_empty() {
        String::new()
    } else {
        format!(", or a registered model: {}", names.join(", "))
    }
}
