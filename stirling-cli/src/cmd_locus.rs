//! `stirling locus`: the poles over a parameter range (root locus), as a table, JSON or SVG.

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use stirling_models::linear::{locus, NewtonOptions};
use stirling_models::plot;

use crate::common::ModelArgs;

/// Arguments of `stirling locus`.
#[derive(Args, Debug)]
pub struct LocusArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The parameter to vary, e.g. Th
    #[arg(long)]
    pub param: String,
    /// First value
    #[arg(long, allow_hyphen_values = true)]
    pub from: f64,
    /// Last value
    #[arg(long, allow_hyphen_values = true)]
    pub to: f64,
    /// Number of values (at least 1)
    #[arg(long, default_value_t = 21)]
    pub steps: usize,
    /// Machine-readable output
    #[arg(long)]
    pub json: bool,
    /// Write locus.svg into this directory
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Compute the locus and print it.
pub fn run(a: &LocusArgs) -> anyhow::Result<()> {
    if a.steps == 0 {
        bail!("--steps must be at least 1");
    }
    let (model, p) = a.model.load()?;
    let values = locus::linspace(a.from, a.to, a.steps);
    let l = locus::locus(
        model.as_ref(),
        &p,
        &a.param,
        &values,
        &NewtonOptions::default(),
    )
    .with_context(|| format!("root locus of `{}` over `{}`", model.name(), a.param))?;
    if let Some(dir) = &a.plot {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        plot::locus::root_locus(&dir.join("locus.svg"), &l)?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&l)?);
        return Ok(());
    }
    println!(
        "root locus of {} over {} ({} values); least stable pair per value:",
        l.model,
        l.param,
        l.points.len()
    );
    for pt in &l.points {
        let top = pt.poles.first();
        let rhp = pt.poles.iter().filter(|p| p.rhp).count();
        match top {
            Some(q) => println!(
                "  {} = {:<12} {:>12.5} {:>+12.5}j   ({rhp} RHP)",
                l.param, pt.value, q.re, q.im
            ),
            None => println!("  {} = {}: no poles", l.param, pt.value),
        }
    }
    Ok(())
}
