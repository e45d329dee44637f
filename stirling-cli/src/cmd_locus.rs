//! `stirling locus`: the poles over a parameter range (root locus), as a table, JSON or SVG.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use stirling_models::linear::{locus, NewtonOptions};
use stirling_models::plot;

use crate::common::{self, files, ranges, ModelArgs};

/// Arguments of `stirling locus`.
#[derive(Args, Debug)]
pub struct LocusArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// The parameter to vary, e.g. Th
    #[arg(long)]
    pub param: String,
    /// First value
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub from: f64,
    /// Last value
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub to: f64,
    /// Number of values (at least 1)
    #[arg(long, default_value_t = 21, allow_negative_numbers = true, value_parser = ranges::at_least_one)]
    pub steps: usize,
    /// Machine-readable output
    #[arg(long)]
    pub json: bool,
    /// Write locus.svg into this directory (created if missing)
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Overwrite an existing figure
    #[arg(long)]
    pub force: bool,
}

/// Compute the locus and print it.
pub fn run(a: &LocusArgs) -> anyhow::Result<()> {
    if let Some(dir) = &a.plot {
        files::prepare_dir(dir, &["locus.svg"], a.force, "--plot")?;
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
        let f = dir.join("locus.svg");
        let unit = model
            .params()
            .iter()
            .find(|q| q.name == a.param)
            .map_or("-", |q| q.unit);
        plot::locus::root_locus(&f, &l, unit)?;
        files::wrote(&f);
    }
    if a.json {
        return common::print_json(&l);
    }
    let mut o = common::stdout();
    writeln!(
        o,
        "root locus of {} over {} ({} values); least stable pair per value:",
        l.model,
        l.param,
        l.points.len()
    )?;
    for pt in &l.points {
        let top = pt.poles.first();
        let rhp = pt.poles.iter().filter(|p| p.rhp).count();
        match top {
            Some(q) => writeln!(
                o,
                "  {} = {:<12} {:>12.5} {:>+12.5}j   ({rhp} RHP)",
                l.param, pt.value, q.re, q.im
            )?,
            None => writeln!(o, "  {} = {}: no poles", l.param, pt.value)?,
        }
    }
    Ok(())
}
