//! What the commands share: which model, at which `n` and closure, with which parameters
//! ([`ModelArgs`](crate::common::ModelArgs)); the checked stdout
//! ([`stdout`](crate::common::stdout)); the rule for files written
//! ([`files`](crate::common::files)); the range checks of numeric options
//! ([`ranges`](crate::common::ranges)); the training and held-out blocks.

mod blocks;
/// One rule for every file the command line writes (`--out FILE`, `--plot DIR`, `--report DIR`).
pub mod files;
/// Value parsers for the numeric options.
pub mod ranges;
/// A limit cycle asked of an engine stable at rest.
pub mod rest;
mod sampling;
mod stdout;

pub use blocks::blocks;
pub use sampling::check_sampling;
pub use stdout::{is_stdout_closed, note, print, print_json, stdout};

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use stirling_dsl::{Closure, Model};

/// Bytes a fit or a diagnosis takes per sample of its record beyond the record itself (1.8 kB
/// measured on a 10-million-row fit, issue 38).
pub const ANALYSIS_BYTES_PER_ROW: f64 = 2000.0;

/// Read a record (`--data`) and the file line of each sample: only the rows from the start of
/// `--train` to the end of `--holdout` when both are given ([`blocks::window`]), under the
/// memory limit of `STIRLING_MAX_RECORD_MB`; with `drop` (`--drop-outliers`) its outliers are
/// replaced by their neighbours' interpolation, each named on stderr.
pub fn read_record(
    path: &std::path::Path,
    drop: bool,
    (train, holdout): (Option<&str>, Option<&str>),
) -> anyhow::Result<(stirling_models::data::Measured, Vec<usize>)> {
    let lim = stirling_models::data::ReadLimits {
        keep: blocks::window(train, holdout),
        work_per_row: ANALYSIS_BYTES_PER_ROW,
        ..Default::default()
    };
    let (mut data, lines) = stirling_models::data::read_csv_within(path, &lim)?;
    if drop {
        repair_outliers(path, &mut data, &lines);
    }
    Ok((data, lines))
}

/// Replace the isolated outliers of `data` (read from `path`, its rows at the file's
/// `lines`), each named on stderr (`--drop-outliers`).
pub fn repair_outliers(
    path: &std::path::Path,
    data: &mut stirling_models::data::Measured,
    lines: &[usize],
) {
    for o in stirling_models::data::outliers::repair(data) {
        let line = lines.get(o.index).copied().unwrap_or(0);
        note(format_args!(
            "{}:{line}: dropped an outlier, {o}",
            path.display()
        ));
    }
}

/// A list option names each item once: `--channels x,x` or `--effect leak=1 --effect leak=2`
/// is refused (which one would count?). `key` gives an item's name (`NAME` of `NAME=VALUE`).
pub fn unique<'a, T: 'a>(
    option: &str,
    items: impl IntoIterator<Item = &'a T>,
    key: impl Fn(&T) -> String,
) -> anyhow::Result<()> {
    let mut seen = std::collections::HashSet::new();
    for it in items {
        let k = key(it);
        if !seen.insert(k.clone()) {
            anyhow::bail!("{option}: `{k}` is named twice: name each once");
        }
    }
    Ok(())
}

/// The record holds a channel the model reads: one of p, p_hot, x, y or a sensor it declares
/// (a record with other columns only would end in a misleading "fewer than two cycles").
pub fn check_channels(
    name: &str,
    model: &dyn Model,
    data: &stirling_models::data::Measured,
) -> anyhow::Result<()> {
    let sensors: Vec<&str> = model.sensors().iter().map(|s| s.name).collect();
    let has_sensor = data
        .others
        .iter()
        .any(|(n, _)| sensors.contains(&n.as_str()));
    if !data
        .channels()
        .iter()
        .any(|c| stirling_models::data::CHANNELS.contains(c))
        && !has_sensor
    {
        let mut reads: Vec<&str> = stirling_models::data::CHANNELS.to_vec();
        for s in sensors {
            if !reads.contains(&s) {
                reads.push(s);
            }
        }
        anyhow::bail!(
            "{}: none of its columns ({}) is a channel `{}` reads ({}): name the columns in the header, e.g. t,p,x,y",
            data.source,
            data.channels().join(", "),
            name,
            reads.join(", ")
        );
    }
    Ok(())
}

/// The bounds of `--bounds FILE` (none without the option).
pub fn bounds_file(
    model: &dyn Model,
    file: Option<&std::path::Path>,
) -> anyhow::Result<Vec<(String, f64, f64)>> {
    Ok(match file {
        Some(f) => stirling_models::bounds::load_bounds(model, f)?,
        None => Vec::new(),
    })
}

/// The regenerator sections and the parameter sources of a model: every command that builds
/// one takes them (declared once here).
#[derive(Args, Debug, Clone)]
pub struct ParamArgs {
    /// Number of regenerator sections (nsection only; default 1)
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::at_least_one)]
    pub n: Option<usize>,
    /// Parameter file (TOML or JSON, parameters by name)
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Override one parameter, e.g. --set Th=650 (repeatable)
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

impl ParamArgs {
    /// `p` with the file's values and then the overrides applied (not validated).
    pub fn apply(&self, model: &dyn Model, p: &mut [f64]) -> anyhow::Result<()> {
        if let Some(f) = &self.params {
            stirling_models::params::apply_file(model, f, p)
                .with_context(|| format!("parameters from {}", f.display()))?;
        }
        for s in &self.set {
            stirling_models::params::apply_override(model, s, p)?;
        }
        Ok(())
    }

    /// The defaults of `model` with the file and the overrides, validated.
    pub fn load(&self, model: &dyn Model) -> anyhow::Result<Vec<f64>> {
        stirling_models::params::load(model, self.params.as_deref(), &self.set)
            .with_context(|| format!("parameters of model `{}`", model.name()))
    }
}

/// Selects a model and its parameters.
#[derive(Args, Debug, Clone)]
pub struct ModelArgs {
    /// Model: schmidt, cv1, cv2, nsection (aliases order4..order8), or an engine file
    /// `engine.stirling` (also given as --model FILE)
    pub model: String,
    /// Inventory closure: full (mass states, default) or frozen (seed's order count)
    #[arg(long, default_value = "full")]
    pub closure: Closure,
    #[command(flatten)]
    pub with: ParamArgs,
}

impl ModelArgs {
    /// The model and its validated parameter vector.
    pub fn load(&self) -> anyhow::Result<(Box<dyn Model>, Vec<f64>)> {
        let model = stirling_models::build(&self.model, self.with.n, self.closure)?;
        let p = self.with.load(model.as_ref())?;
        Ok((model, p))
    }
}
