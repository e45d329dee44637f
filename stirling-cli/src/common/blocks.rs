//! The training and held-out blocks of `fit` and `diagnose`: each inside the record, and the
//! held-out block after the training block, without overlap (it validates a prediction forward
//! from the training block).

use anyhow::{anyhow, bail};
use stirling_models::data::{parse_span, Measured};

/// A block as given (`Some`) or left to the command's default (`None`).
pub type Block = Option<(f64, f64)>;

/// `--train` and `--holdout` checked against the record and each other; a missing training
/// block stands for the command's default, the first `default_train` fraction of the record.
pub fn blocks(
    train: Option<&str>,
    holdout: Option<&str>,
    data: &Measured,
    default_train: f64,
) -> anyhow::Result<(Block, Block)> {
    let span = |opt: &str, s: Option<&str>| {
        s.map(|s| parse_span(s, data).map_err(|e| anyhow!("{opt} {s}: {e}")))
            .transpose()
    };
    let tr = span("--train", train)?;
    let ho = span("--holdout", holdout)?;
    let (t0, t1) = (data.t[0], data.t[data.t.len() - 1]);
    let (a, what) = match (tr, train) {
        (Some(t), Some(s)) => (t, format!("--train {s}")),
        _ => {
            let a = (t0, t0 + default_train * (t1 - t0));
            let pct = (100.0 * default_train).round();
            let w = format!(
                "the default training block {}:{} s (the first {pct} % of the record; give --train)",
                short(a.0),
                short(a.1)
            );
            (a, w)
        }
    };
    if let (Some(h), Some(s)) = (ho, holdout) {
        if h.1 <= a.0 {
            bail!(
                "--holdout {s} comes before {what}: the held-out block must follow the training block"
            );
        }
        if h.0 < a.1 {
            bail!(
                "--holdout {s} overlaps {what}: the held-out block must start at or after {} s",
                short(a.1)
            );
        }
    }
    Ok((tr, ho))
}

/// The rows a command needs when both blocks are given: from the start of `--train` to the end
/// of `--holdout` (an empty end reaches the record's end); `None` (every row) otherwise, or when
/// either does not parse (its error comes from [`blocks`] once the record is read).
pub fn window(train: Option<&str>, holdout: Option<&str>) -> Option<(f64, f64)> {
    let end = |s: &str, first: bool, open: f64| -> Option<f64> {
        let (a, b) = s.split_once(':')?;
        let v = if first { a } else { b }.trim();
        if v.is_empty() {
            Some(open)
        } else {
            v.parse::<f64>().ok().filter(|v| v.is_finite())
        }
    };
    let a = end(train?, true, f64::NEG_INFINITY)?;
    let b = end(holdout?, false, f64::INFINITY)?;
    (b > a).then_some((a, b))
}

/// Six decimals, no trailing zeros.
fn short(v: f64) -> String {
    let s = format!("{:.6}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".into()
    } else {
        s.into()
    }
}
