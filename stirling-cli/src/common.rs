//! What the commands share: which model, at which `n` and closure, with which parameters
//! ([`ModelArgs`]); the checked stdout ([`stdout`]); the rule for files written ([`files`]);
//! the range checks of numeric options ([`ranges`]); the training and held-out blocks.

mod blocks;
pub mod files;
pub mod ranges;
mod stdout;

pub use blocks::blocks;
pub use stdout::{is_stdout_closed, note, print, print_json, stdout};

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use stirling_dsl::{Closure, Model};

/// Selects a model and its parameters.
#[derive(Args, Debug, Clone)]
pub struct ModelArgs {
    /// Model: schmidt, cv1, cv2, nsection (aliases order4..order8)
    pub model: String,
    /// Number of regenerator sections (nsection only; default 1)
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::at_least_one)]
    pub n: Option<usize>,
    /// Inventory closure: full (mass states, default) or frozen (seed's order count)
    #[arg(long, default_value = "full")]
    pub closure: Closure,
    /// Parameter file (TOML or JSON, parameters by name)
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Override one parameter, e.g. --set Th=650 (repeatable)
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

impl ModelArgs {
    /// The model and its validated parameter vector.
    pub fn load(&self) -> anyhow::Result<(Box<dyn Model>, Vec<f64>)> {
        let model = stirling_models::build(&self.model, self.n, self.closure)?;
        let p = stirling_models::params::load(model.as_ref(), self.params.as_deref(), &self.set)
            .with_context(|| format!("parameters of model `{}`", model.name()))?;
        Ok((model, p))
    }
}
