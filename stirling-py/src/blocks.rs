//! The training and held-out blocks of a fit or a diagnosis, `(a, b)` in seconds: each inside
//! the record (the library's span check, one sample interval of slack at each end), the
//! held-out block after the training block (as the command line's `--train`/`--holdout`).

use stirling_models::data::{parse_span, Measured};

use crate::errors::{Failure, Res};

/// A block as given, or the default (`None`).
pub type Block = Option<(f64, f64)>;

fn span(name: &str, b: Block, data: &Measured) -> Res<Block> {
    let Some((a, z)) = b else { return Ok(None) };
    // `{:?}` writes each time so that it reads back as the same number
    parse_span(&format!("{a:?}:{z:?}"), data)
        .map(Some)
        .map_err(|e| Failure::option(format!("{name} = ({a}, {z}): {e}")))
}

/// `train` and `holdout` checked against the record and each other; without `train` the
/// training block is the first `default_train` fraction of the record.
pub fn blocks(
    train: Block,
    holdout: Block,
    data: &Measured,
    default_train: f64,
) -> Res<(Block, Block)> {
    let tr = span("train", train, data)?;
    let ho = span("holdout", holdout, data)?;
    let (t0, t1) = (data.t[0], data.t[data.t.len() - 1]);
    let a = tr.unwrap_or((t0, t0 + default_train * (t1 - t0)));
    if let Some(h) = ho {
        if h.1 <= a.0 || h.0 < a.1 {
            return Err(Failure::option(format!(
                "holdout = ({}, {}) must follow the training block ({}, {}) without overlap",
                h.0, h.1, a.0, a.1
            )));
        }
    }
    Ok((tr, ho))
}
