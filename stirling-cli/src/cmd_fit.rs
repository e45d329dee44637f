//! `stirling fit`: the two-stage identification (mechanics driven by measured pressure, gas
//! driven by measured displacements) with estimates, intervals, correlations and fit %.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use clap::Args;
use stirling_dsl::Closure;
use stirling_models::data::check_uniform;
use stirling_models::fit::free_run::FreeRun;
use stirling_models::fit::multiple_shooting::MultipleShooting;
use stirling_models::fit::report::{Estimate, FitStats};
use stirling_models::fit::{self, FitOptions, Identification, Series, StageFit};
use stirling_models::plot::series::measured_vs_model;

use crate::common::{self, files, ranges};

/// The figures `--plot` writes (one per stage and channel).
const FIGURES: [&str; 3] = ["stage1_*.svg", "stage2_*.svg", "free_run_*.svg"];

/// Arguments of `stirling fit`.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// Model: cv1, cv2, nsection (aliases order5..order8), or an engine file `engine.stirling`
    /// (also given as --model FILE)
    pub model: String,
    /// Starting parameters: sections, file, overrides
    #[command(flatten)]
    pub with: common::ParamArgs,
    /// Measured data (CSV: t and p, x, y; p_hot optional)
    #[arg(long)]
    pub data: PathBuf,
    /// Free parameters, comma-separated (default: those the model declares with `free`, else
    /// kd,kp,bd,bp,hh,hk,Rf where used)
    #[arg(long, value_delimiter = ',')]
    pub free: Option<Vec<String>>,
    /// Bounds of free parameters (TOML `kd = [100.0, 2000.0]` or JSON), over those the model
    /// declares; the fit stays inside them
    #[arg(long, value_name = "FILE")]
    pub bounds: Option<PathBuf>,
    /// Training block a:b in seconds (default: first 70 %)
    #[arg(long, allow_hyphen_values = true)]
    pub train: Option<String>,
    /// Held-out block c:d in seconds, after the training block (default: the rest)
    #[arg(long, allow_hyphen_values = true)]
    pub holdout: Option<String>,
    /// Machine-readable output
    #[arg(long)]
    pub json: bool,
    /// Write measured-vs-model SVGs into this directory (created if missing)
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Overwrite existing figures
    #[arg(long)]
    pub force: bool,
    /// Replace isolated outlier samples (more than 12 robust sd off the cubic through their
    /// neighbours) by that interpolation, each named on stderr; without it a record with
    /// outliers is refused
    #[arg(long)]
    pub drop_outliers: bool,
    /// Refine by multiple shooting over segments of about this many cycles (on up to 0.5 s
    /// of the training block) before the free run
    #[arg(long, value_name = "CYCLES", allow_negative_numbers = true, value_parser = ranges::cycles)]
    pub multiple_shooting: Option<f64>,
    /// Restart stage 1 (the mechanics driven by the measured pressure) from the measured body
    /// states every this many cycles, e.g. 0.5: for engines whose bodies hit end stops or
    /// other stiff contacts, where one run over the block can settle on another response of
    /// the driven mechanics than the engine's (default: one run)
    #[arg(long, value_name = "CYCLES", allow_negative_numbers = true, value_parser = ranges::restart_cycles)]
    pub restart_cycles: Option<f64>,
}

pub fn run(a: &FitArgs) -> anyhow::Result<()> {
    if let Some(dir) = &a.plot {
        files::prepare_dir(dir, &FIGURES, a.force, "--plot")?;
    }
    // outliers are repaired once the model says which column is a flywheel's angle: a
    // counter's wraps at a revolution are steps, not outliers
    let (mut data, lines) =
        common::read_record(&a.data, false, (a.train.as_deref(), a.holdout.as_deref()))?;
    check_uniform(&data, Some(&lines))?;
    let (train, holdout) = common::blocks(a.train.as_deref(), a.holdout.as_deref(), &data, 0.7)?;
    let model = stirling_models::build(&a.model, a.with.n, Closure::Full)?;
    fit::kinematic::unwrap_angle(model.as_ref(), &mut data);
    if a.drop_outliers {
        common::repair_outliers(&a.data, &mut data, &lines);
    }
    common::check_channels(&a.model, model.as_ref(), &data)?;
    let p0 = a.with.load(model.as_ref())?;
    common::check_sampling(model.as_ref(), &p0, &data, train, 0.7)?;
    let bounds = common::bounds_file(model.as_ref(), a.bounds.as_deref())?;
    let opts = FitOptions {
        free: a.free.clone(),
        bounds,
        multiple_shooting: a
            .multiple_shooting
            .map(|c| fit::multiple_shooting::MsOptions {
                cycles: c,
                ..Default::default()
            }),
        train,
        holdout,
        restart_cycles: a.restart_cycles,
        ..Default::default()
    };
    let res = fit::identify(model.as_ref(), &p0, &data, &opts)?;
    if let Some(dir) = &a.plot {
        plots(dir, &res)?;
    }
    if a.json {
        common::print_json(&res)?;
    } else {
        print_text(&mut common::stdout(), &a.data, &res)?;
    }
    // a result that is not an optimum does not stand: say so with a non-zero exit
    for st in [&res.stage1, &res.stage2].into_iter().flatten() {
        if !st.converged {
            anyhow::bail!(
                "{} did not converge in {} iterations: the estimates above are not an optimum ({})",
                st.stage,
                st.iterations,
                likely_cause(st)
            );
        }
    }
    Ok(())
}

/// Least training fit (%) of a channel the stage fits, below which a stage that did not
/// converge is blamed on the record's columns rather than on its length.
const POOR_FIT: f64 = 50.0;

/// What to do about a stage that did not converge: when it fits no channel even roughly
/// (sign-flipped or swapped positions ended here with "a longer record may help"), the
/// columns are the likely cause; otherwise more data or better starting values.
fn likely_cause(st: &stirling_models::fit::StageFit) -> String {
    let train: Vec<(&str, f64)> = st
        .fits
        .iter()
        .filter(|f| f.block == "train")
        .map(|f| (f.channel.as_str(), f.fit_percent))
        .collect();
    let best = train.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
    if best.is_finite() && best < POOR_FIT {
        let list: Vec<String> = train.iter().map(|(c, f)| format!("{c} {f:.0} %")).collect();
        return format!(
            "it fits no channel even roughly: {} on the training block; a longer record will not \
             help. Likely causes: a position channel sign-flipped (measured in the other \
             direction), x and y swapped, positions not in m or a pressure not of the cold side: \
             check the columns against `stirling info` and the rig's sign convention",
            list.join(", ")
        );
    }
    "a longer record, more excitation or better starting values may help".into()
}

fn plot_series(path: &Path, title: &str, s: &Series) -> anyhow::Result<()> {
    Ok(measured_vs_model(
        path,
        title,
        &s.channel,
        &s.t,
        &s.measured,
        &s.model,
    )?)
}

fn plots(dir: &Path, res: &Identification) -> anyhow::Result<()> {
    for (k, st) in [&res.stage1, &res.stage2].into_iter().enumerate() {
        for s in st.iter().flat_map(|s| &s.series) {
            let f = dir.join(format!("stage{}_{}.svg", k + 1, s.channel));
            plot_series(
                &f,
                &format!("stage {}: {} measured vs model", k + 1, s.channel),
                s,
            )?;
            files::wrote(&f);
        }
    }
    for s in res.free_run.iter().flat_map(|f| &f.series) {
        let f = dir.join(format!("free_run_{}.svg", s.channel));
        plot_series(&f, &format!("free run: {} measured vs model", s.channel), s)?;
        files::wrote(&f);
    }
    Ok(())
}

fn print_text(o: &mut impl Write, data: &Path, res: &Identification) -> io::Result<()> {
    writeln!(
        o,
        "model {} (n = {}), data {}, train {:.3}:{:.3} s{}",
        res.model,
        res.n,
        data.display(),
        res.train.0,
        res.train.1,
        res.holdout
            .map(|h| format!(", holdout {:.3}:{:.3} s", h.0, h.1))
            .unwrap_or_default()
    )?;
    for st in [&res.stage1, &res.stage2].into_iter().flatten() {
        print_stage(o, st)?;
    }
    if let Some(ms) = &res.multiple_shooting {
        print_multiple_shooting(o, ms)?;
    }
    if let Some(fr) = &res.free_run {
        print_free_run(o, fr)?;
    }
    for n in &res.notes {
        writeln!(o, "NOTE: {n}")?;
    }
    writeln!(o, "\ntotal {:.2} s", res.seconds)?;
    Ok(())
}

/// `converged` or `NOT converged`.
fn convergence(converged: bool) -> &'static str {
    if converged {
        "converged"
    } else {
        "NOT converged"
    }
}

/// One row of the estimates table.
fn print_estimate(o: &mut impl Write, e: &Estimate) -> io::Result<()> {
    writeln!(
        o,
        "  {:<14} {:>14.6e} {:>14.6e} {:>12.3e}   [{:.6e}, {:.6e}]",
        e.name, e.initial, e.value, e.std_error, e.ci_low, e.ci_high
    )
}

/// A stage: its estimates, their correlation matrix, warnings and fits.
fn print_stage(o: &mut impl Write, st: &StageFit) -> io::Result<()> {
    writeln!(
        o,
        "\n{} ({} iterations, {} evaluations, {}, {:.2} s)",
        st.stage,
        st.iterations,
        st.evaluations,
        convergence(st.converged),
        st.seconds
    )?;
    writeln!(
        o,
        "  {:<14} {:>14} {:>14} {:>12} {:>28}",
        "quantity", "initial", "estimate", "std error", "95 % interval"
    )?;
    for e in &st.stats.estimates {
        print_estimate(o, e)?;
    }
    print_correlation(o, &st.stats)?;
    for w in &st.stats.warnings {
        writeln!(o, "  WARNING: {w}")?;
    }
    for f in &st.fits {
        writeln!(
            o,
            "  fit {:<6} {:<8} {:>7.2} %  (rms {:.3e}, {} samples)",
            f.channel, f.block, f.fit_percent, f.rms, f.samples
        )?;
    }
    Ok(())
}

/// The correlation matrix of the estimates, names shortened to fit the columns.
fn print_correlation(o: &mut impl Write, stats: &FitStats) -> io::Result<()> {
    let names: Vec<&str> = stats.estimates.iter().map(|e| e.name.as_str()).collect();
    writeln!(o, "  correlation:")?;
    writeln!(
        o,
        "  {:>12} {}",
        "",
        names
            .iter()
            .map(|n| format!("{:>9}", &n[..n.len().min(9)]))
            .collect::<String>()
    )?;
    for (i, row) in stats.correlation.iter().enumerate() {
        writeln!(
            o,
            "  {:>12} {}",
            &names[i][..names[i].len().min(12)],
            row.iter().map(|v| format!("{v:>9.3}")).collect::<String>()
        )?;
    }
    Ok(())
}

/// The multiple-shooting refinement: model estimates, warnings (segment pairs counted), fits.
fn print_multiple_shooting(o: &mut impl Write, ms: &MultipleShooting) -> io::Result<()> {
    writeln!(
        o,
        "\nmultiple shooting ({} segments, {} iterations, {}, {:.2} s, largest defect {:.2e})",
        ms.segments.len(),
        ms.iterations,
        convergence(ms.converged),
        ms.seconds,
        ms.segments.iter().map(|s| s.defect).fold(0.0, f64::max)
    )?;
    for e in ms
        .stats
        .estimates
        .iter()
        .filter(|e| !e.name.starts_with("seg"))
    {
        print_estimate(o, e)?;
    }
    // collinear segment initial states (fast gas modes) are expected: count them only
    let (seg, other): (Vec<&String>, Vec<&String>) =
        ms.stats.warnings.iter().partition(|w| w.contains("`seg"));
    for w in other {
        writeln!(o, "  WARNING: {w}")?;
    }
    if !seg.is_empty() {
        writeln!(
            o,
            "  note: {} nearly collinear pairs involve segment initial states (see --json)",
            seg.len()
        )?;
    }
    for f in &ms.fits {
        writeln!(
            o,
            "  fit {:<6} {:<8} {:>7.2} %",
            f.channel, f.block, f.fit_percent
        )?;
    }
    Ok(())
}

/// The free-run validation: fits, cycle features, the displacer's phase drift.
fn print_free_run(o: &mut impl Write, fr: &FreeRun) -> io::Result<()> {
    writeln!(
        o,
        "\nfree run from the measured state at {:.3} s (to {:.3} s; short window {:.3} s)",
        fr.block.0, fr.block.1, fr.short_window
    )?;
    for f in &fr.fits {
        writeln!(
            o,
            "  fit {:<6} {:<15} {:>7.2} %  (rms {:.3e})",
            f.channel, f.block, f.fit_percent, f.rms
        )?;
    }
    if let (Some(m), Some(s)) = (&fr.measured, &fr.simulated) {
        writeln!(
            o,
            "  frequency   measured {:.4} Hz, model {:.4} Hz",
            m.frequency, s.frequency
        )?;
        for (((c, am), (_, asim)), ((_, pm), (_, psim))) in m
            .amplitude
            .iter()
            .zip(&s.amplitude)
            .zip(m.phase.iter().zip(&s.phase))
        {
            writeln!(
                o,
                "  {c:<6} amplitude {am:.4e} / {asim:.4e}, phase vs x {pm:+.4} / {psim:+.4} rad"
            )?;
        }
    }
    if let Some(l) = fr.x_phase_lag {
        writeln!(o, "  displacer phase drift at the block end {l:+.4} rad")?;
    }
    Ok(())
}
