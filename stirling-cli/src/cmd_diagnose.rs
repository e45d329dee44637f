//! `stirling diagnose`: the sim-to-real gap diagnosis (where, which effect, how far), and its
//! self-check on rig data with withheld effects.

use std::path::PathBuf;

use anyhow::{bail, Context};
use clap::Args;
use stirling_models::data::{parse_span, read_csv};
use stirling_models::diagnose::{self, selfcheck, DiagnoseOptions};

/// Arguments of `stirling diagnose`.
#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Model with an augmented member: cv1 or nsection (aliases order5, order7, order8)
    pub model: Option<String>,
    /// Number of regenerator sections (nsection)
    #[arg(long)]
    pub n: Option<usize>,
    /// Measured data (CSV: t and p, x, y; p_hot optional)
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Starting parameters (TOML or JSON by name)
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Override a starting parameter (repeatable)
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Candidate effects: all, or a comma-separated list
    #[arg(long, default_value = "all")]
    pub effects: String,
    /// Training block a:b in seconds (default: first 60 %)
    #[arg(long)]
    pub train: Option<String>,
    /// Held-out block c:d in seconds (default: the rest)
    #[arg(long)]
    pub holdout: Option<String>,
    /// Spread of the prior on the nominal parameters around their starting values, as a log
    /// standard deviation (0.5: a factor 1.65 at one standard deviation; 0: no prior)
    #[arg(long, default_value_t = diagnose::DEFAULT_PRIOR)]
    pub prior: f64,
    /// Write report.md and SVG figures into this directory
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Run the self-check (rig data with each effect withheld) instead of diagnosing a file;
    /// without MODEL, every effect of the library on the smallest model it applies to (cv1,
    /// else nsection n = 2)
    #[arg(long)]
    pub self_check: bool,
    /// Self-check: record length (s)
    #[arg(long, default_value_t = 2.0)]
    pub t_end: f64,
    /// Self-check: sample rate (Hz)
    #[arg(long, default_value_t = 2000.0)]
    pub rate: f64,
    /// Self-check: strengths as multiples of the typical values, comma-separated
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub strengths: Vec<f64>,
    /// Machine-readable output
    #[arg(long)]
    pub json: bool,
}

/// The prior spread: `None` for 0, an error for a negative or non-finite value.
fn prior_arg(v: f64) -> anyhow::Result<Option<f64>> {
    if !v.is_finite() || v < 0.0 {
        bail!("--prior must be a finite log standard deviation >= 0 (0: no prior), got {v}");
    }
    Ok((v > 0.0).then_some(v))
}

fn effects_arg(s: &str) -> Option<Vec<String>> {
    if s.trim() == "all" {
        None
    } else {
        Some(
            s.split(',')
                .map(|v| v.trim().to_string())
                .filter(|v| !v.is_empty())
                .collect(),
        )
    }
}

pub fn run(a: &DiagnoseArgs) -> anyhow::Result<()> {
    if a.self_check {
        let opts = selfcheck::SelfCheckOptions {
            model: a.model.clone().unwrap_or_else(|| "cv1".into()),
            n: a.n,
            effects: effects_arg(&a.effects),
            strengths: a.strengths.clone(),
            t_end: a.t_end,
            rate: a.rate,
            diagnose: DiagnoseOptions {
                prior: prior_arg(a.prior)?,
                ..Default::default()
            },
            ..Default::default()
        };
        let json = a.json;
        let progress = |c: &selfcheck::Case| {
            if !json {
                eprintln!(
                    "{:<12} {:<16} x{:<4} -> {:<20} rank {:>4} closure {} [{}, {}]  {:>6.1} s  {}",
                    c.model,
                    c.truth,
                    c.strength,
                    c.verdict,
                    c.truth_rank.map(|r| r.to_string()).unwrap_or("-".into()),
                    c.closure_fraction
                        .map(|v| format!("{v:.2}"))
                        .unwrap_or("-".into()),
                    c.ci_low.map(|v| format!("{v:.2}")).unwrap_or("-".into()),
                    c.ci_high.map(|v| format!("{v:.2}")).unwrap_or("-".into()),
                    c.seconds,
                    if c.pass { "pass" } else { "FAIL" }
                );
            }
        };
        // without a model: every effect of the library, each on the smallest model it fits
        let sc = if a.model.is_some() {
            selfcheck::run(&opts, progress)?
        } else {
            selfcheck::run_library(&opts, progress)?
        };
        if json {
            println!("{}", serde_json::to_string_pretty(&sc)?);
        } else {
            println!("{}", selfcheck::matrix_markdown(&sc));
            println!("{}/{} cases pass, {:.1} s", sc.passed, sc.total, sc.seconds);
        }
        if sc.passed < sc.total {
            bail!(
                "self-check: {} of {} cases fail",
                sc.total - sc.passed,
                sc.total
            );
        }
        return Ok(());
    }
    let (Some(model_name), Some(path)) = (a.model.as_ref(), a.data.as_ref()) else {
        bail!("usage: stirling diagnose <model> --data FILE ... (or --self-check)");
    };
    let data = read_csv(path)?;
    let (model, mut p0) = diagnose::nominal_model(model_name, a.n)?;
    if let Some(f) = &a.params {
        stirling_models::params::apply_file(model.as_ref(), f, &mut p0)
            .with_context(|| format!("parameters from {}", f.display()))?;
    }
    for s in &a.set {
        stirling_models::params::apply_override(model.as_ref(), s, &mut p0)?;
    }
    let mut opts = DiagnoseOptions {
        effects: effects_arg(&a.effects),
        prior: prior_arg(a.prior)?,
        ..Default::default()
    };
    if let Some(s) = &a.train {
        opts.train = Some(parse_span(s, &data).map_err(anyhow::Error::msg)?);
    }
    if let Some(s) = &a.holdout {
        opts.holdout = Some(parse_span(s, &data).map_err(anyhow::Error::msg)?);
    }
    let d = diagnose::diagnose(model.as_ref(), &p0, &data, &opts)?;
    if let Some(dir) = &a.report {
        let p = diagnose::report::write(&d, &data, dir).map_err(anyhow::Error::msg)?;
        if !a.json {
            println!("report: {}", p.display());
        }
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&d)?);
        return Ok(());
    }
    println!(
        "model {} (n = {}), data {}, train {:.3}:{:.3} s, held out {:.3}:{:.3} s",
        d.model,
        d.n,
        path.display(),
        d.train.0,
        d.train.1,
        d.holdout.0,
        d.holdout.1
    );
    println!("\ngap before (held out):");
    for c in &d.gap_before.channels {
        println!(
            "  {:<6} rms {:.4e}  noise {:.4e}  ratio {:.3}",
            c.channel, c.rms, c.noise, c.ratio
        );
    }
    for s in &d.gap_before.shifts {
        println!(
            "  {:<6} start {:.4e} -> calibrated {:.4e} (x{:.3}{})",
            s.name,
            s.start,
            s.calibrated,
            s.factor,
            s.prior_sd
                .map(|z| format!(", {z:+.2} prior sd"))
                .unwrap_or_default()
        );
    }
    let l = &d.localization;
    println!(
        "  subsystems: mechanics {:.3}, gas {:.3} noise variances; dominant {}",
        l.mechanics_error, l.gas_error, l.dominant_subsystem
    );
    for c in &l.channels {
        println!(
            "  {:<6} harmonics {:?} (noise level {:.2e})",
            c.channel,
            c.harmonics
                .iter()
                .map(|v| format!("{v:.2e}"))
                .collect::<Vec<_>>(),
            c.harmonic_noise
        );
        println!(
            "  {:<6} phase bins {:?}",
            c.channel,
            c.phase_bins
                .iter()
                .map(|v| format!("{v:.2}"))
                .collect::<Vec<_>>()
        );
    }
    println!("\nranking:");
    println!(
        "  {:<16} {:>10} {:>10} {:>10} {:>10} {:>22}  params",
        "effect", "score", "p", "dBIC", "holdout", "closure [95% CI]"
    );
    for r in &d.ranking {
        let o = |v: Option<f64>| v.map(|v| format!("{v:.3}")).unwrap_or("-".into());
        println!(
            "  {:<16} {:>10.2} {:>10.2e} {:>10} {:>10} {:>22}  {}",
            r.effect,
            r.score,
            r.p_value,
            o(r.delta_bic),
            o(r.holdout_error),
            format!(
                "{} [{}, {}]",
                o(r.closure_fraction),
                o(r.ci_low),
                o(r.ci_high)
            ),
            r.params
                .iter()
                .map(|q| format!(
                    "{}={:.3e} [{:.3e}, {:.3e}]",
                    q.name, q.value, q.ci_low, q.ci_high
                ))
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    println!(
        "\nverdict: {}{} ({})",
        d.verdict.verdict,
        d.verdict
            .effect
            .as_ref()
            .map(|e| format!(" `{e}`"))
            .unwrap_or_default(),
        d.verdict.reason
    );
    println!("{} fits (nominal and joint), {:.1} s", d.fits, d.seconds);
    Ok(())
}
