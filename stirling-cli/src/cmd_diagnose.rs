//! `stirling diagnose`: the sim-to-real gap diagnosis (where, which effect, how far), and its
//! self-check on rig data with withheld effects.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use anyhow::bail;
use clap::Args;
use stirling_models::data::check_uniform;
use stirling_models::diagnose::localize::Localization;
use stirling_models::diagnose::{self, selfcheck, DiagnoseOptions, Diagnosis, RankEntry};

use crate::common::{self, files, ranges};

/// What `--report` writes: the report and its figures (named after the channels).
const REPORT: [&str; 2] = ["report.md", "*.svg"];

/// Arguments of `stirling diagnose`.
#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Model with an augmented member: cv1, nsection or nsection_ext (aliases order5, order7,
    /// order8), or an engine file `engine.stirling` with its `effect` items (also --model FILE)
    pub model: Option<String>,
    /// Starting parameters: sections, file, overrides
    #[command(flatten)]
    pub with: common::ParamArgs,
    /// Measured data (CSV: t and p, x, y; p_hot optional)
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Candidate effects: all, or a comma-separated list
    #[arg(long, default_value = "all")]
    pub effects: String,
    /// Bounds of the nominal parameters (TOML `kd = [100.0, 2000.0]` or JSON), over those the
    /// model declares; the calibration stays inside them
    #[arg(long, value_name = "FILE")]
    pub bounds: Option<PathBuf>,
    /// Restart stage 1 from the measured body states every this many cycles, from the first
    /// step on (what the diagnosis's second pass for end stops does by itself, at 0.25, when
    /// one run explains nothing): for records whose bodies hit stops; the steps then follow
    /// the restarted rule (docs/diagnosis.md, Method step 6)
    #[arg(long, value_name = "CYCLES", allow_negative_numbers = true, value_parser = ranges::restart_cycles)]
    pub restart_cycles: Option<f64>,
    /// Nominal parameters the calibration frees, comma-separated (default: those the model
    /// declares `free`; on a kinematic engine, its film coefficients and flow resistances)
    #[arg(long, value_delimiter = ',')]
    pub free: Option<Vec<String>>,
    /// Training block a:b in seconds (default: first 60 %)
    #[arg(long, allow_hyphen_values = true)]
    pub train: Option<String>,
    /// Held-out block c:d in seconds, after the training block (default: the rest)
    #[arg(long, allow_hyphen_values = true)]
    pub holdout: Option<String>,
    /// Spread of the prior on the nominal parameters around their starting values, as a log
    /// standard deviation (0.5: a factor 1.65 at one standard deviation; 0: no prior)
    #[arg(long, default_value_t = diagnose::DEFAULT_PRIOR, allow_negative_numbers = true)]
    pub prior: f64,
    /// Fit every candidate, not only those whose score is significant (slower; the verdict
    /// does not change, the ranking of the non-significant candidates is filled in)
    #[arg(long)]
    pub fit_all: bool,
    /// Integration tolerance of the driven runs (relative, and absolute on the scaled states;
    /// the fit's own default is 1e-7)
    #[arg(long, default_value_t = diagnose::DIAGNOSE_RTOL)]
    pub rtol: f64,
    /// Family-wise significance level of the candidates' score screen (Bonferroni over the
    /// candidates)
    #[arg(long, default_value_t = 0.01)]
    pub alpha: f64,
    /// Write report.md and SVG figures into this directory (created if missing)
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Overwrite an existing report and figures
    #[arg(long)]
    pub force: bool,
    /// Replace isolated outlier samples (more than 12 robust sd off the cubic through their
    /// neighbours) by that interpolation, each named on stderr; without it a record with
    /// outliers is refused
    #[arg(long)]
    pub drop_outliers: bool,
    /// Run the verdict self-check instead of diagnosing a file: rig records (p,x,y) with each
    /// library effect at each strength, with causes outside the library and clean records,
    /// thresholds tuned on the tuning seeds and the confusion matrix of verdicts on the
    /// evaluation seeds (MODEL: default nsection, --n default 2)
    #[arg(long)]
    pub self_check: bool,
    /// Self-check: record length (s, > 0)
    #[arg(long, default_value_t = 2.0, allow_negative_numbers = true, value_parser = ranges::positive)]
    pub t_end: f64,
    /// Self-check: sample rate (Hz, > 0)
    #[arg(long, default_value_t = 2000.0, allow_negative_numbers = true, value_parser = ranges::positive)]
    pub rate: f64,
    /// Self-check: strengths as multiples of the typical values (> 0), comma-separated
    #[arg(long, value_delimiter = ',', default_value = "1,2", allow_negative_numbers = true, value_parser = ranges::positive)]
    pub strengths: Vec<f64>,
    /// Self-check: channels of the rig records (the seed's p,x,y by default; add p_hot for the
    /// richer rig, dropped on single-CV models)
    #[arg(long, value_delimiter = ',', default_value = "p,x,y")]
    pub channels: Vec<String>,
    /// Self-check: first noise seed (tuning seeds from it, evaluation seeds from it + 1000)
    #[arg(long, default_value_t = 5, allow_negative_numbers = true, value_parser = ranges::seed)]
    pub seed: u64,
    /// Self-check: noise seeds per effect and outside case, TUNE:EVAL (thresholds are chosen
    /// on the tuning seeds, the accuracy is counted on the evaluation seeds)
    #[arg(long, default_value = "1:1", value_parser = ranges::split_counts)]
    pub seeds: (usize, usize),
    /// Self-check: clean records (each its own seed and starting-parameter perturbation),
    /// TUNE:EVAL
    #[arg(long, default_value = "10:20", value_parser = ranges::split_counts)]
    pub clean: (usize, usize),
    /// Self-check: causes outside the library (truth models the diagnosis does not know):
    /// all, none, or a comma-separated list of h_speed, spring_cubic
    #[arg(long, default_value = "all")]
    pub outside: String,
    /// Self-check: strengths of the outside causes, as multiples of their unit (> 0)
    #[arg(long, value_delimiter = ',', default_value = "1", allow_negative_numbers = true, value_parser = ranges::positive)]
    pub outside_strengths: Vec<f64>,
    /// Self-check: every pair of the library effects at this multiple of their units (0: no
    /// pairs)
    #[arg(long, default_value_t = 1.0, value_parser = ranges::non_negative)]
    pub pair_strength: f64,
    /// Self-check: every library effect beside every outside cause, each at this multiple of
    /// its unit (0: none); right when the verdict is `unexplained` or names the library
    /// effect alone with an unexplained remainder
    #[arg(long, default_value_t = 1.0, value_parser = ranges::non_negative)]
    pub mixed_strength: f64,
    /// Self-check: only the cases of these truths, by the labels of the confusion matrix
    /// (e.g. `end_stops+leak,sensor_gain,clean`); each keeps the seeds and start it has in the
    /// whole self-check of the same other options (a start's seed follows the case's place in
    /// the whole plan, so with another `--seeds` or `--clean` the same label draws new records)
    #[arg(long, value_delimiter = ',')]
    pub cases: Option<Vec<String>>,
    /// Self-check: keep every case's record and start in OUT/records (`case<k>.csv`,
    /// `case<k>.start.json`), to diagnose one again by hand with `--data` and `--params`
    #[arg(long)]
    pub keep_records: bool,
    /// Self-check: cases run at once (each diagnosis also uses both cores)
    #[arg(long, default_value_t = 2, value_parser = ranges::at_least_one)]
    pub jobs: usize,
    /// Self-check: directory for selfcheck.json and selfcheck.md (created)
    #[arg(long, default_value = "selfcheck")]
    pub out: PathBuf,
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

fn alpha_arg(v: f64) -> anyhow::Result<f64> {
    if !(v.is_finite() && v > 0.0 && v < 1.0) {
        bail!("--alpha must be a significance level in (0, 1), got {v}");
    }
    Ok(v)
}

fn rtol_arg(v: f64) -> anyhow::Result<f64> {
    if !(v.is_finite() && v > 0.0 && v < 1e-2) {
        bail!("--rtol must be a tolerance in (0, 0.01), got {v}");
    }
    Ok(v)
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
        return run_self_check(a);
    }
    let (Some(model_name), Some(path)) = (a.model.as_ref(), a.data.as_ref()) else {
        bail!("usage: stirling diagnose <model> --data FILE ... (or --self-check)");
    };
    // Files stamped from here on are this run's: taken before the diagnosis, as the file
    // system's clock is coarser than SystemTime (a stamp taken just before writing can be later
    // than the files' times).
    let start = std::time::SystemTime::now();
    if let Some(dir) = &a.report {
        files::prepare_dir(dir, &REPORT, a.force, "--report")?;
    }
    let (data, lines) = common::read_record(
        path,
        a.drop_outliers,
        (a.train.as_deref(), a.holdout.as_deref()),
    )?;
    check_uniform(&data, Some(&lines))?;
    let (train, holdout) = common::blocks(a.train.as_deref(), a.holdout.as_deref(), &data, 0.6)?;
    let (model, mut p0) = diagnose::nominal_model(model_name, a.with.n)?;
    common::check_channels(model_name, model.as_ref(), &data)?;
    a.with.apply(model.as_ref(), &mut p0)?;
    common::check_sampling(model.as_ref(), &p0, &data, train, 0.6)?;
    let bounds = common::bounds_file(model.as_ref(), a.bounds.as_deref())?;
    let opts = DiagnoseOptions {
        fit: stirling_models::fit::FitOptions {
            bounds,
            free: a
                .free
                .as_ref()
                .map(|v| v.iter().map(|s| s.trim().to_string()).collect()),
            restart_cycles: a.restart_cycles,
            ..Default::default()
        },
        effects: effects_arg(&a.effects),
        prior: prior_arg(a.prior)?,
        rtol: rtol_arg(a.rtol)?,
        alpha: alpha_arg(a.alpha)?,
        train,
        holdout,
        progress: Some(|line: &str| common::note(line)),
        fit_all: a.fit_all,
        ..Default::default()
    };
    let d = diagnose::diagnose(model.as_ref(), &p0, &data, &opts)?;
    if let Some(dir) = &a.report {
        let p = diagnose::report::write(&d, &data, dir)?;
        for f in files::matching(dir, &REPORT, Some(start))? {
            files::wrote(&f);
        }
        if !a.json {
            writeln!(common::stdout(), "report: {}", p.display())?;
        }
    }
    if a.json {
        return common::print_json(&d);
    }
    Ok(print_text(&mut common::stdout(), path, &d)?)
}

/// An evaluation set without a case is refused before any record is made (it failed after
/// the tuning cases' 44 s): no evaluation seed of an effect, an outside cause or a pair, and no
/// clean evaluation record.
fn empty_evaluation(a: &DiagnoseArgs, outside: Option<&Vec<String>>) -> anyhow::Result<()> {
    let effect_cases = a.seeds.1 > 0
        && (effects_arg(&a.effects).is_none_or(|e| !e.is_empty())
            || outside.is_none_or(|o| !o.is_empty())
            || a.pair_strength > 0.0);
    if effect_cases || a.clean.1 > 0 {
        return Ok(());
    }
    bail!(
        "the self-check's evaluation set is empty (--seeds {}:{} --clean {}:{}): nothing to count \
         verdicts on; give at least one evaluation seed, e.g. --seeds {}:1 or --clean {}:1",
        a.seeds.0,
        a.seeds.1,
        a.clean.0,
        a.clean.1,
        a.seeds.0,
        a.clean.0
    )
}

/// `--self-check`: the verdict self-check (rig records with library effects, causes outside
/// the library and clean records; thresholds tuned on one seed set, verdicts counted on the
/// other); fails when the evaluation accuracy is under 90 % or false alarms over 5 %.
fn run_self_check(a: &DiagnoseArgs) -> anyhow::Result<()> {
    let outside = match a.outside.trim() {
        "all" => None,
        "none" => Some(Vec::new()),
        s => effects_arg(s),
    };
    empty_evaluation(a, outside.as_ref())?;
    common::unique("--channels", &a.channels, |c| c.trim().to_string())?;
    common::unique("--strengths", &a.strengths, |v| v.to_string())?;
    common::unique("--outside-strengths", &a.outside_strengths, |v| {
        v.to_string()
    })?;
    if let Some(o) = &outside {
        common::unique("--outside", o, |c| c.clone())?;
    }
    let model = a.model.clone().unwrap_or_else(|| "nsection".into());
    let n = match model.as_str() {
        "nsection" => a.with.n.or(Some(2)),
        _ => a.with.n,
    };
    let opts = selfcheck::VerdictOptions {
        model,
        n,
        effects: effects_arg(&a.effects),
        strengths: a.strengths.clone(),
        outside,
        outside_strengths: a.outside_strengths.clone(),
        pair_strength: (a.pair_strength > 0.0).then_some(a.pair_strength),
        mixed_strength: (a.mixed_strength > 0.0).then_some(a.mixed_strength),
        seeds: a.seeds,
        clean: a.clean,
        t_end: a.t_end,
        rate: a.rate,
        channels: a.channels.clone(),
        seed: a.seed,
        jobs: a.jobs,
        only: a.cases.clone(),
        records: a.keep_records.then(|| a.out.join("records")),
        diagnose: DiagnoseOptions {
            prior: prior_arg(a.prior)?,
            rtol: rtol_arg(a.rtol)?,
            alpha: alpha_arg(a.alpha)?,
            ..Default::default()
        },
        ..Default::default()
    };
    // before the run, not after it: an earlier self-check is kept unless --force
    files::prepare_dir(
        &a.out,
        &["selfcheck.json", "selfcheck.md"],
        a.force,
        "--out",
    )?;
    if a.keep_records {
        let records = a.out.join("records");
        let kept = ["case*.csv", "case*.start.json"];
        files::prepare_dir(&records, &kept, a.force, "--keep-records")?;
    }
    let clock = std::time::Instant::now();
    let progress = |c: &selfcheck::outcome::Outcome, done: usize, total: usize| {
        let el = clock.elapsed().as_secs_f64();
        let eta = el / done as f64 * (total - done) as f64;
        common::note(format!(
            "[{done}/{total}, {el:.0} s, ~{eta:.0} s left] {}",
            selfcheck::report::case_row(c)
        ));
    };
    let sc = selfcheck::run_verdicts(&opts, &progress)?;
    let [json, md] = selfcheck::report::write(&sc, &a.out)?;
    if a.json {
        common::print_json(&sc)?;
    } else {
        let mut o = common::stdout();
        writeln!(o, "{}", sc.eval_default.markdown())?;
        writeln!(o, "{}", selfcheck::report::headline(&sc))?;
        writeln!(o, "wrote {} and {}", json.display(), md.display())?;
    }
    // the verdicts as the diagnosis gave them, not the tuned relabelling (a bound)
    let e = &sc.eval_default;
    let (acc, fa) = (e.accuracy(), e.false_alarm_rate());
    if !(acc >= 0.9) || fa > 0.05 {
        bail!(
            "self-check: verdict accuracy {}/{} on the evaluation set, false alarms {}/{} (the bar: at least 90 % right, at most 5 % false alarms)",
            e.right, e.total, e.false_alarms, e.clean
        );
    }
    Ok(())
}

/// The diagnosis as text: the verdict first (what the user reads), then the evidence.
fn print_text(o: &mut impl Write, path: &Path, d: &Diagnosis) -> io::Result<()> {
    writeln!(
        o,
        "model {} (n = {}), data {}, train {:.3}:{:.3} s, held out {:.3}:{:.3} s",
        d.model,
        d.n,
        path.display(),
        d.train.0,
        d.train.1,
        d.holdout.0,
        d.holdout.1
    )?;
    let named = if d.verdict.effects.is_empty() {
        d.verdict.effect.iter().cloned().collect::<Vec<_>>()
    } else {
        d.verdict.effects.clone()
    };
    writeln!(
        o,
        "\nverdict: {}{}{} ({})",
        d.verdict.verdict,
        named.iter().map(|e| format!(" `{e}`")).collect::<String>(),
        match (
            d.verdict.unexplained_remainder && d.verdict.verdict == "effect",
            d.verdict.free_run_worse,
        ) {
            (true, true) =>
                " + an unexplained remainder, and a free run worse than the calibrated model's",
            (true, false) => " + an unexplained remainder",
            (false, true) => ", but a free run worse than the calibrated model's",
            (false, false) => "",
        },
        d.verdict.reason
    )?;
    print_steps(o, d)?;
    match (&d.simulation_gap, &d.simulation_gap_note) {
        (Some(g), _) => writeln!(
            o,
            "\nthe calibrated model simulated on its own over the held-out block ({} cycles; error = model - measured, 95 % interval over cycles):\n{}",
            g.cycles,
            g.markdown()
        )?,
        (None, Some(why)) => writeln!(o, "\nsimulated gap: not measured ({why})")?,
        _ => {}
    }
    print_gap_before(o, d)?;
    print_localization(o, &d.localization)?;
    print_ranking(o, &d.ranking)?;
    writeln!(
        o,
        "\n{} fits (nominal and joint), {:.1} s",
        d.fits, d.seconds
    )
}

/// The explanation step by step: what each step named, closed and left.
fn print_steps(o: &mut impl Write, d: &Diagnosis) -> io::Result<()> {
    if d.steps.is_empty() {
        return Ok(());
    }
    writeln!(
        o,
        "\nsteps (each refits the nominal parameters and every effect named so far):"
    )?;
    for s in &d.steps {
        writeln!(o, "  {}. {:<24} {}", s.step, s.label(), step_summary(s))?;
        for q in &s.params {
            let iv = if q.ci_low.is_finite() {
                format!("[{:.4e}, {:.4e}]", q.ci_low, q.ci_high)
            } else {
                "(no interval)".into()
            };
            writeln!(o, "       {} = {:.4e} {iv} {}", q.name, q.value, q.unit)?;
        }
    }
    Ok(())
}

/// What a step closed and left; for a step without a simulated closure (end stops named
/// from the measured acceleration alone), why.
fn step_summary(s: &stirling_models::diagnose::types::Step) -> String {
    if !s.has_closure() {
        return s
            .simulation_gap_note
            .clone()
            .unwrap_or_else(|| "no simulated closure".into());
    }
    let left: Vec<String> = s
        .channels
        .iter()
        .map(|c| format!("{} {:.2}", c.channel, c.ratio))
        .collect();
    format!("{}; rms/noise {}", s.closure_text(), left.join(", "))
}

/// The driven subsystems' held-out gap per channel and the calibrated parameters.
fn print_gap_before(o: &mut impl Write, d: &Diagnosis) -> io::Result<()> {
    writeln!(o, "\ngap before (held out, driven subsystems):")?;
    for c in &d.gap_before.channels {
        writeln!(
            o,
            "  {:<6} rms {:.4e}  noise {:.4e}  ratio {:.3}",
            c.channel, c.rms, c.noise, c.ratio
        )?;
    }
    for s in &d.gap_before.shifts {
        let sd = s.prior_sd.map(|z| format!(", {z:+.2} prior sd"));
        writeln!(
            o,
            "  {:<6} start {:.4e} -> calibrated {:.4e} (x{:.3}{})",
            s.name,
            s.start,
            s.calibrated,
            s.factor,
            sd.unwrap_or_default()
        )?;
    }
    Ok(())
}

/// Where: subsystems, harmonics and phase bins per channel.
fn print_localization(o: &mut impl Write, l: &Localization) -> io::Result<()> {
    // a subsystem the record does not drive (a kinematic engine's mechanics: its angle is
    // prescribed) has no error: said so, not printed as NaN
    let err = |e: f64| {
        if e.is_finite() {
            format!("{e:.3}")
        } else {
            "not fitted".into()
        }
    };
    writeln!(
        o,
        "  subsystems: mechanics {}, gas {} noise variances; dominant {}",
        err(l.mechanics_error),
        err(l.gas_error),
        l.dominant_subsystem
    )?;
    let list = |v: &[f64], f: fn(&f64) -> String| v.iter().map(f).collect::<Vec<_>>();
    for c in &l.channels {
        writeln!(
            o,
            "  {:<6} harmonics {:?} (noise level {:.2e})",
            c.channel,
            list(&c.harmonics, |v| format!("{v:.2e}")),
            c.harmonic_noise
        )?;
        writeln!(
            o,
            "  {:<6} phase bins {:?}",
            c.channel,
            list(&c.phase_bins, |v| format!("{v:.2}"))
        )?;
    }
    Ok(())
}

/// Which: the candidates in rank order.
fn print_ranking(o: &mut impl Write, ranking: &[RankEntry]) -> io::Result<()> {
    writeln!(o, "\nranking:")?;
    writeln!(
        o,
        "  {:<16} {:>10} {:>10} {:>10} {:>10} {:>22}  params",
        "effect", "score", "p", "dBIC", "holdout", "closure [95% CI]"
    )?;
    let fmt = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.3}"));
    for r in ranking {
        let closure = format!(
            "{} [{}, {}]",
            fmt(r.closure_fraction),
            fmt(r.ci_low),
            fmt(r.ci_high)
        );
        let params: Vec<String> = r
            .params
            .iter()
            .map(|q| {
                format!(
                    "{}={:.3e} [{:.3e}, {:.3e}]",
                    q.name, q.value, q.ci_low, q.ci_high
                )
            })
            .collect();
        writeln!(
            o,
            "  {:<16} {:>10.2} {:>10.2e} {:>10} {:>10} {:>22}  {}",
            r.effect,
            r.score,
            r.p_value,
            fmt(r.delta_bic),
            fmt(r.holdout_error),
            closure,
            params.join(" ")
        )?;
    }
    Ok(())
}
