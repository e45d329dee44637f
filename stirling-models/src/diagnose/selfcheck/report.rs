//! The verdict self-check as a person reads it (Markdown) and as a program does (JSON).

use std::path::{Path, PathBuf};

use super::outcome::Outcome;
use super::plan::is_right;
use super::verdicts::VerdictCheck;
use crate::diagnose::DiagnoseError;

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.2}"))
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.1} %", 100.0 * v)
    } else {
        "-".into()
    }
}

/// One case as a table row (and a progress line).
pub fn case_row(c: &Outcome) -> String {
    let right = if is_right(&c.expected, &c.tuned_verdict) {
        "right"
    } else {
        "WRONG"
    };
    format!(
        "| {} | {:?} | {} | {} | {} | {} | {} {} [{}, {}] | {} ({}) | {:.0} |",
        c.index,
        c.split,
        c.label,
        c.truth.strength(),
        c.seed,
        c.verdict,
        c.closure_of.as_deref().unwrap_or("-"),
        opt(c.closure),
        opt(c.ci_low),
        opt(c.ci_high),
        c.tuned_verdict,
        if c.error.is_some() { "error" } else { right },
        c.seconds
    )
}

/// Right / total per class of record on the evaluation set (the verdicts as run).
fn class_line(v: &VerdictCheck) -> String {
    v.eval_default
        .classes
        .iter()
        .map(|(k, r, n)| format!("{k} {r}/{n} ({})", pct(*r as f64 / *n as f64)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The summary lines: accuracy and false alarms on the evaluation set, the verdicts as the
/// diagnosis gave them first; then the tuned thresholds' relabelling (each run's steps cut
/// where a step fails them: a bound on what those thresholds would give, not a run at them;
/// docs/diagnosis.md, run-j).
pub fn headline(v: &VerdictCheck) -> String {
    let t = &v.tuned.thresholds;
    let classes = class_line(v);
    format!(
        "evaluation set: verdicts right {}/{} ({}), false alarms on clean records {}/{} ({}), the diagnosis's default thresholds, as run\n\
         by class: {classes}\n\
         thresholds tuned on {} tuning cases: score level {:.1e} (family-wise), held-out BIC change < {}, closure lower bound > {} ({}/{} right there); relabelled with them (each run's steps cut where one fails them, not a run at them): {}/{} right, {}/{} false alarms\n\
         {} cases, {:.0} s wall, {:.0} s summed over cases",
        v.eval_default.right, v.eval_default.total, pct(v.eval_default.accuracy()), v.eval_default.false_alarms, v.eval_default.clean, pct(v.eval_default.false_alarm_rate()),
        v.tuned.total, t.alpha, t.strong_bic, t.min_closure, v.tuned.right, v.tuned.total,
        v.eval.right, v.eval.total, v.eval.false_alarms, v.eval.clean,
        v.cases.len(), v.seconds, v.case_seconds
    )
}

/// The whole self-check as Markdown.
pub fn markdown(v: &VerdictCheck) -> String {
    let mut s = format!(
        "# Verdict self-check: {} on {} ({} s at {} Hz)\n\n{}\n\n",
        v.model,
        v.channels.join(","),
        v.t_end,
        v.rate,
        headline(v).replace('\n', "\n\n")
    );
    s += "## Evaluation set, the diagnosis's default thresholds (as run)\n\n";
    s += &v.eval_default.markdown();
    s += "\n## Evaluation set, relabelled with the tuned thresholds (steps cut, not a run)\n\n";
    s += &v.eval.markdown();
    s += "\n## Tuning set (thresholds chosen here)\n\n";
    s += &v.tune.markdown();
    s += "\n## What each truth does to the record (mean against the clean records)\n\n";
    s += "| truth | strength | x amplitude | y amplitude | p amplitude | frequency |\n|---|---|---|---|---|---|\n";
    for g in &v.signatures {
        s += &format!(
            "| {} | {} | {:+.1} % | {:+.1} % | {:+.1} % | {:+.2} % |\n",
            g.label,
            g.strength,
            100.0 * g.x_amp,
            100.0 * g.y_amp,
            100.0 * g.p_amp,
            100.0 * g.freq
        );
    }
    s += "\n## Cases\n\n| # | set | truth | strength | seed | verdict (default) | closure of [95 % CI] | tuned verdict (right?) | time (s) |\n|---|---|---|---|---|---|---|---|---|\n";
    for c in &v.cases {
        s += &case_row(c);
        s.push('\n');
    }
    for c in v.cases.iter().filter(|c| c.error.is_some()) {
        s += &format!(
            "\ncase {} failed: {}\n",
            c.index,
            c.error.as_deref().unwrap_or("")
        );
    }
    s
}

/// Write `selfcheck.json` and `selfcheck.md` into `dir` (created); returns their paths.
pub fn write(v: &VerdictCheck, dir: &Path) -> Result<[PathBuf; 2], DiagnoseError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| DiagnoseError::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let (json, md) = (dir.join("selfcheck.json"), dir.join("selfcheck.md"));
    let text = serde_json::to_string_pretty(v).map_err(|e| DiagnoseError::Io {
        path: json.clone(),
        source: std::io::Error::other(e),
    })?;
    // whole or not at all (the existing ones were refused up front without --force)
    let atomic = |path: &std::path::Path, bytes: &[u8]| {
        crate::output::write_atomic(path, bytes, true)
            .map_err(|e| io(path)(std::io::Error::other(e)))
    };
    atomic(&json, text.as_bytes())?;
    atomic(&md, markdown(v).as_bytes())?;
    Ok([json, md])
}
