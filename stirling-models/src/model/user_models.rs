//! Models a user's crate registers at start-up, so that the command line (and every lookup by name)
//! serves them like the family: a binary calls [`register`](crate::model::user_models::register)
//! for each of its declared engines, then runs the command line (`stirling_cli::main()`).

use std::sync::{OnceLock, RwLock};

use stirling_dsl::{Closure, Model, ModelError};

/// Builds a model at `n` sections and a closure.
pub type Constructor = fn(usize, Closure) -> Result<Box<dyn Model>, ModelError>;

/// A registered model.
#[derive(Clone, Copy, Debug)]
pub struct UserModel {
    /// The name the command line takes (`stirling fit NAME`).
    pub name: &'static str,
    pub summary: &'static str,
    /// Whether `n` (regenerator sections) applies.
    pub has_array: bool,
    pub build: Constructor,
    /// Its augmented member (effects at their null), for `stirling diagnose` and `rig --effect`.
    pub augmented: Option<Constructor>,
}

/// Why a model cannot be registered.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RegisterError {
    #[error("cannot register `{0}`: a family model or alias has that name")]
    FamilyName(String),
    #[error("cannot register `{0}` twice")]
    Twice(String),
}

fn table() -> &'static RwLock<Vec<UserModel>> {
    static TABLE: OnceLock<RwLock<Vec<UserModel>>> = OnceLock::new();
    TABLE.get_or_init(|| RwLock::new(Vec::new()))
}

/// Register a model under its name (refused for a family name or alias, or a second time).
pub fn register(m: UserModel) -> Result<(), RegisterError> {
    let family = crate::FAMILY
        .iter()
        .any(|e| e.name == m.name || e.aliases.contains(&m.name));
    // the library's names too (`cv1_fx`, `nsection_ext`, ...): lookups by name try them first
    if family || crate::effects::in_library(m.name) {
        return Err(RegisterError::FamilyName(m.name.into()));
    }
    let mut t = table().write().unwrap_or_else(|e| e.into_inner());
    if t.iter().any(|u| u.name == m.name) {
        return Err(RegisterError::Twice(m.name.into()));
    }
    t.push(m);
    Ok(())
}

/// The registered models, in registration order.
pub fn registered() -> Vec<UserModel> {
    table().read().unwrap_or_else(|e| e.into_inner()).clone()
}

/// The registered model of that name.
pub fn find(name: &str) -> Option<UserModel> {
    registered().into_iter().find(|u| u.name == name)
}
