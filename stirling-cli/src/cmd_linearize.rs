//! `stirling linearize`: equilibrium, closed-loop poles, the loop broken at a pressure-force
//! channel and its margins (docs/physics.md sections 6-7); `--json` prints the `LinearReport`,
//! `--plot DIR` writes the pole map and the Bode diagram as SVG.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use serde::Serialize;
use stirling_dsl::Model;
use stirling_models::linear::export::{self, StateSpaceExport};
use stirling_models::linear::{self, LinearOptions, LinearReport, Linearization, Margins, Pole};
use stirling_models::plot;

use crate::common::{self, files, ModelArgs};

/// The figures `--plot` writes.
const FIGURES: [&str; 2] = ["poles.svg", "bode.svg"];

/// Arguments of `stirling linearize`.
#[derive(Args, Debug)]
pub struct LinearizeArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Loop channel: `pressure` (single-pressure models: schmidt, cv1) or a body (piston,
    /// displacer); default: pressure where there is one, else piston
    #[arg(long)]
    pub channel: Option<String>,
    /// Machine-readable output: the report and, as `state_space`, the export of --ss
    #[arg(long)]
    pub json: bool,
    /// Write the state-space A, B, C, D of the broken and the closed loop, the Bode data and
    /// the pole tables as JSON (python-control and MATLAB read it; see the user guide)
    #[arg(long, value_name = "FILE")]
    pub ss: Option<PathBuf>,
    /// Write poles.svg and bode.svg into this directory (created if missing)
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Overwrite existing figures and an existing --ss file
    #[arg(long)]
    pub force: bool,
    /// All poles by the dense route at any size (default: all up to 400 states, above that the
    /// dominant ones by sparse shift-invert Arnoldi)
    #[arg(long, conflicts_with = "dominant")]
    pub all_poles: bool,
    /// The K rightmost poles by the sparse route at any size
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=200))]
    pub dominant: Option<u32>,
}

/// `--json`: the report with the state-space export.
#[derive(Serialize)]
struct Json<'a> {
    #[serde(flatten)]
    report: &'a LinearReport,
    state_space: &'a StateSpaceExport,
}

/// Run the analysis and print it.
pub fn run(a: &LinearizeArgs) -> anyhow::Result<()> {
    if let Some(dir) = &a.plot {
        files::prepare_dir(dir, &FIGURES, a.force, "--plot")?;
    }
    if let Some(f) = &a.ss {
        files::prepare_file(f, a.force, "--ss")?;
    }
    let (model, p) = a.model.load()?;
    let poles = match (a.all_poles, a.dominant) {
        (true, _) => linear::PoleRequest::All,
        (false, Some(k)) => linear::PoleRequest::Dominant(k as usize),
        (false, None) => linear::PoleRequest::Auto,
    };
    let opts = LinearOptions {
        channel: a.channel.clone(),
        poles,
        ..Default::default()
    };
    let lin = linear::linearize(model.as_ref(), &p, &opts)
        .with_context(|| format!("linearizing `{}`", model.name()))?;
    let report = lin.report(model.as_ref());
    if let Some(dir) = &a.plot {
        plots(dir, model.as_ref(), &lin)?;
    }
    let ss = (a.json || a.ss.is_some()).then(|| export::export(model.as_ref(), &lin));
    if let (Some(f), Some(ss)) = (&a.ss, &ss) {
        files::write_text(f, &serde_json::to_string_pretty(ss)?, a.force, "--ss")?;
    }
    if let (true, Some(ss)) = (a.json, &ss) {
        common::print_json(&Json {
            report: &report,
            state_space: ss,
        })
    } else {
        Ok(print_text(&mut common::stdout(), &report)?)
    }
}

fn plots(dir: &Path, model: &dyn Model, lin: &Linearization) -> anyhow::Result<()> {
    let tag = plot::bode::model_tag(model);
    let poles = dir.join(FIGURES[0]);
    plot::poles::pole_map(
        &poles,
        &format!("Poles of {tag}"),
        &lin.dynamics.poles,
        &lin.open_loop.poles,
    )?;
    files::wrote(&poles);
    let bode_svg = dir.join(FIGURES[1]);
    plot::bode::loop_bode(&bode_svg, &tag, lin)?;
    files::wrote(&bode_svg);
    Ok(())
}

fn opt(v: Option<f64>, prec: usize) -> String {
    v.map_or("none".into(), |v| format!("{v:.prec$}"))
}

fn print_pole(o: &mut impl Write, p: &Pole) -> io::Result<()> {
    let flag = if p.rhp { "  RHP" } else { "" };
    writeln!(
        o,
        "  {:>14.6} {:>+14.6}j   {:>10.4} rad/s {:>9.4} Hz   zeta {:>8.4}{flag}",
        p.re, p.im, p.freq_rad_s, p.freq_hz, p.damping_ratio
    )
}

fn print_text(o: &mut impl Write, r: &LinearReport) -> io::Result<()> {
    writeln!(
        o,
        "model {} (n = {}, closure {}), {} states",
        r.model, r.n, r.closure, r.n_states
    )?;
    let eq = &r.equilibrium;
    writeln!(
        o,
        "equilibrium: residual max|f| = {:.3e}, scaled {:.3e} 1/s, {} Newton iterations",
        eq.residual, eq.scaled_residual, eq.iterations
    )?;
    if let Some(inv) = &r.inventory_mode {
        writeln!(
            o,
            "inventory mode: eigenvalue {:.3e}, mass conservation defect {:.1e} (removed)",
            inv.eigenvalue, inv.conservation_defect
        )?;
    }
    writeln!(o, "poles: {}", r.route.describe(r.n_states))?;
    writeln!(
        o,
        "closed-loop poles ({} in the right half plane):",
        r.rhp_count
    )?;
    for p in &r.poles {
        print_pole(o, p)?;
    }
    let l = &r.loop_break;
    writeln!(
        o,
        "loop broken at the {} input ({}); open-loop poles ({} RHP):",
        l.channel, l.unit, l.open_loop_rhp_count
    )?;
    for p in &l.open_loop_poles {
        print_pole(o, p)?;
    }
    print_margins(o, &r.margins)
}

/// The selected gain and phase margins, then every crossover.
fn print_margins(o: &mut impl Write, m: &Margins) -> io::Result<()> {
    writeln!(
        o,
        "margins: Gm = {} dB at {} rad/s, Pm = {} deg at {} rad/s",
        opt(m.gain_db, 3),
        opt(m.phase_crossover_rad_s, 2),
        opt(m.phase_deg, 2),
        opt(m.gain_crossover_rad_s, 2)
    )?;
    for g in &m.all_gain {
        writeln!(
            o,
            "  phase crossover {:>10.3} rad/s: Gm = {:.3} dB",
            g.phase_crossover_rad_s, g.gain_db
        )?;
    }
    for p in &m.all_phase {
        writeln!(
            o,
            "  gain crossover  {:>10.3} rad/s: Pm = {:.2} deg",
            p.gain_crossover_rad_s, p.phase_deg
        )?;
    }
    Ok(())
}
