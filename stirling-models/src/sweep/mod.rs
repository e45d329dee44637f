//! Design sweeps: a grid over any parameters of any model; at each point the equilibrium's dominant
//! pole, whether the engine runs, and where it does the limit cycle's frequency, strokes, phase,
//! work and power. The points run on every core (rayon); a shard runs every `N`-th point of the
//! grid, and [`merge`](crate::sweep::merge) joins the shards' results into the sweep an unsharded
//! run gives.

/// The points: axes, ties, shards.
pub mod grid;
/// One point's evaluation.
pub mod point;
/// The results as CSV.
pub mod table;

use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use crate::sim::SimOptions;
use grid::{Axis, Tie};
use point::{Evaluate, PointResult};

/// Why a sweep could not run (a failed point is not an error: it is recorded).
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    #[error("--grid `{given}`: {why}")]
    Axis { given: String, why: String },
    #[error("--tie `{given}`: {why}")]
    Tie { given: String, why: String },
    #[error("--shard `{given}`: expected i/N with 1 <= i <= N, e.g. 3/16")]
    Shard { given: String },
    #[error("`{model}` has no parameter `{name}` (in {origin}): see `stirling info {model}`")]
    UnknownParameter {
        name: String,
        model: String,
        origin: &'static str,
    },
    #[error("parameter `{name}` is swept twice")]
    Twice { name: String },
    #[error("a sweep needs at least one --grid axis")]
    NoAxes,
    #[error("the grid has {points} points, more than the {max} one run takes: use --shard i/N")]
    TooLarge { points: usize, max: usize },
    #[error("cannot merge: {why}")]
    Merge { why: String },
}

/// The largest grid one process runs (a sharded grid may be larger).
pub const MAX_POINTS: usize = 10_000_000;

/// What to sweep and how.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub axes: Vec<Axis>,
    pub ties: Vec<Tie>,
    /// Longest settling time of each limit cycle (s); `None`: poles only.
    pub settle: Option<f64>,
    /// `(i, N)`: run shard `i` of `N`.
    pub shard: Option<(usize, usize)>,
    pub sim: SimOptions,
}

/// The results of a sweep (or of one shard of it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    pub model: String,
    pub n: usize,
    pub axes: Vec<Axis>,
    /// The unit of each axis's parameter.
    #[serde(default)]
    pub units: Vec<String>,
    pub ties: Vec<Tie>,
    /// The base parameters every point starts from (name, value), before its axes and ties:
    /// shards of one sweep share them (empty in files written before they were recorded).
    #[serde(default)]
    pub base: Vec<(String, f64)>,
    /// Points in the whole grid.
    pub total: usize,
    /// The shard these results are (`None`: the whole grid, or merged shards).
    pub shard: Option<(usize, usize)>,
    /// The points run, by grid index.
    pub points: Vec<PointResult>,
}

/// Check the names, then run the points (of the shard) on every core; `progress` gets
/// called once per finished point.
pub fn run(
    model: &dyn Model,
    base: &[f64],
    opts: &SweepOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<Sweep, SweepError> {
    check(model, opts)?;
    let total = grid::count(&opts.axes);
    if total > MAX_POINTS && opts.shard.is_none() {
        return Err(SweepError::TooLarge {
            points: total,
            max: MAX_POINTS,
        });
    }
    let indices = match opts.shard {
        Some((i, n)) => grid::shard(total, i, n),
        None => (0..total).collect(),
    };
    let eval = Evaluate {
        model,
        base,
        axes: &opts.axes,
        ties: &opts.ties,
        settle: opts.settle,
        sim: opts.sim,
    };
    let points = {
        use rayon::prelude::*;
        indices
            .par_iter()
            .map(|&k| {
                let r = eval.point(k, grid::point(&opts.axes, k));
                progress();
                r
            })
            .collect()
    };
    Ok(Sweep {
        model: model.name().into(),
        n: model.n(),
        axes: opts.axes.clone(),
        units: opts
            .axes
            .iter()
            .filter_map(|a| model.param_index(&a.name))
            .map(|i| model.params()[i].unit.to_string())
            .collect(),
        ties: opts.ties.clone(),
        base: model
            .params()
            .iter()
            .zip(base)
            .map(|(q, v)| (q.name.to_string(), *v))
            .collect(),
        total,
        shard: opts.shard,
        points,
    })
}

/// A shard as `i/N` (`whole grid` without one).
fn shard_label(shard: Option<(usize, usize)>) -> String {
    shard.map_or("(whole grid)".into(), |(i, n)| format!("{i}/{n}"))
}

/// The first base parameter that differs between two shards, as `name a here, b there`.
fn base_difference(a: &[(String, f64)], b: &[(String, f64)]) -> Option<String> {
    if a.len() != b.len() {
        return Some(format!("{} against {} parameters", a.len(), b.len()));
    }
    a.iter()
        .zip(b)
        .find(|(x, y)| x.0 != y.0 || x.1.to_bits() != y.1.to_bits())
        .map(|(x, y)| {
            format!(
                "`{}` {:e} in the first, `{}` {:e} in this one",
                x.0, x.1, y.0, y.1
            )
        })
}

/// Every axis and tie names a parameter of the model, no axis twice.
fn check(model: &dyn Model, opts: &SweepOptions) -> Result<(), SweepError> {
    if opts.axes.is_empty() {
        return Err(SweepError::NoAxes);
    }
    let known = |name: &str, origin| {
        model
            .param_index(name)
            .map(|_| ())
            .ok_or_else(|| SweepError::UnknownParameter {
                name: name.into(),
                model: model.name().into(),
                origin,
            })
    };
    for (k, a) in opts.axes.iter().enumerate() {
        known(&a.name, "--grid")?;
        if opts.axes[..k].iter().any(|b| b.name == a.name) {
            return Err(SweepError::Twice {
                name: a.name.clone(),
            });
        }
    }
    for t in &opts.ties {
        known(&t.follower, "--tie")?;
        known(&t.leader, "--tie")?;
    }
    Ok(())
}

/// Join shards of one sweep: same model, axes and ties, no point twice. The result is
/// complete (`shard: None`) when every point of the grid is there.
pub fn merge(parts: Vec<Sweep>) -> Result<Sweep, SweepError> {
    let mut it = parts.into_iter();
    let mut out = it.next().ok_or_else(|| SweepError::Merge {
        why: "no sweep files given".into(),
    })?;
    for p in it {
        let same = p.model == out.model && p.n == out.n && p.axes == out.axes;
        if !same || p.ties != out.ties || p.total != out.total {
            return Err(SweepError::Merge {
                why: format!(
                    "shard {} is of another sweep (model, n, axes, ties or grid size differ)",
                    shard_label(p.shard)
                ),
            });
        }
        if let Some(why) = base_difference(&out.base, &p.base) {
            return Err(SweepError::Merge {
                why: format!(
                    "shard {} was run from other base parameters ({why}): it belongs to another sweep",
                    shard_label(p.shard)
                ),
            });
        }
        out.points.extend(p.points);
    }
    out.points.sort_by_key(|r| r.index);
    if let Some(w) = out.points.windows(2).find(|w| w[0].index == w[1].index) {
        return Err(SweepError::Merge {
            why: format!("point {} is in two of the files", w[0].index),
        });
    }
    out.shard = None;
    if out.points.len() != out.total {
        return Err(SweepError::Merge {
            why: format!(
                "{} of the grid's {} points are there: a shard is missing",
                out.points.len(),
                out.total
            ),
        });
    }
    Ok(out)
}
