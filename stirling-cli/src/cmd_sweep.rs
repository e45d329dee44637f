//! `stirling sweep`: a grid over any parameters of a model; per point the dominant pole at
//! rest, whether the engine runs, and its limit cycle (frequency, strokes, phase, work,
//! power). CSV, JSON and, over two parameters, a map; `--shard i/N` runs one slice and
//! `stirling sweep-merge` joins the slices.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use stirling_models::plot::axes;
use stirling_models::plot::sweep_map::{self, Cell, Map};
use stirling_models::sim::SimOptions;
use stirling_models::sweep::grid::{self, Axis, Tie};
use stirling_models::sweep::point::Outcome;
use stirling_models::sweep::{self, table, Sweep, SweepOptions};

use crate::common::{self, files, ranges, ModelArgs};

/// The files a sweep writes into its folder.
const OUTPUTS: [&str; 3] = ["sweep.csv", "sweep.json", "sweep_map.svg"];

/// Arguments of `stirling sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// An axis: NAME=a:b:k (k values from a to b) or NAME=v1,v2,... (repeatable; the grid is
    /// their product, the last axis varying fastest)
    #[arg(long = "grid", value_name = "AXIS", required = true)]
    pub grid: Vec<String>,
    /// FOLLOWER=LEADER: the follower keeps its ratio to the leader (repeatable). Sweeping
    /// Pmean ties Pb=Pmean unless --untie
    #[arg(long = "tie", value_name = "F=L")]
    pub tie: Vec<String>,
    /// No default ties
    #[arg(long)]
    pub untie: bool,
    /// Longest settling time of each limit cycle (s)
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true, value_parser = ranges::positive)]
    pub settle: f64,
    /// Poles only: no limit cycles
    #[arg(long)]
    pub poles_only: bool,
    /// Run slice i of N (every N-th point), for a job array; join with `stirling sweep-merge`
    #[arg(long, value_name = "i/N")]
    pub shard: Option<String>,
    /// Worker threads (default: every core)
    #[arg(long, value_parser = ranges::at_least_one)]
    pub threads: Option<usize>,
    /// Output folder: sweep.csv, sweep.json and, over two parameters, sweep_map.svg
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing outputs
    #[arg(long)]
    pub force: bool,
}

/// Arguments of `stirling sweep-merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The shards' sweep.json files
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Output folder of the joined sweep
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite existing outputs
    #[arg(long)]
    pub force: bool,
}

pub fn run(a: &SweepArgs) -> anyhow::Result<()> {
    let (model, p) = a.model.load()?;
    let axes: Vec<Axis> = a
        .grid
        .iter()
        .map(|s| Axis::parse(s))
        .collect::<Result<_, _>>()?;
    let mut ties: Vec<Tie> = a
        .tie
        .iter()
        .map(|s| Tie::parse(s))
        .collect::<Result<_, _>>()?;
    if !a.untie {
        let has = |n: &str| model.param_index(n).is_some();
        let extra: Vec<Tie> = grid::default_ties(&axes, has)
            .into_iter()
            .filter(|t| !ties.iter().any(|u| u.follower == t.follower))
            .collect();
        ties.extend(extra);
    }
    let opts = SweepOptions {
        axes,
        ties,
        settle: (!a.poles_only).then_some(a.settle),
        shard: a.shard.as_deref().map(grid::parse_shard).transpose()?,
        sim: SimOptions::default(),
    };
    files::prepare_dir(&a.out, &OUTPUTS, a.force, "--out")?;
    let total = match opts.shard {
        Some((i, n)) => grid::shard(grid::count(&opts.axes), i, n).len(),
        None => grid::count(&opts.axes),
    };
    for t in &opts.ties {
        common::note(format_args!("tie: {} follows {}", t.follower, t.leader));
    }
    let bar = progress_bar(total as u64);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .context("cannot start the worker threads")?;
    let s = pool.install(|| sweep::run(model.as_ref(), &p, &opts, &|| bar.inc(1)))?;
    bar.finish_and_clear();
    write(&a.out, &s, a.force)
}

pub fn merge(a: &MergeArgs) -> anyhow::Result<()> {
    let mut parts = Vec::new();
    for f in &a.files {
        let text =
            std::fs::read_to_string(f).with_context(|| format!("cannot read {}", f.display()))?;
        let s: Sweep = serde_json::from_str(&text).with_context(|| {
            format!(
                "{}: not a sweep.json written by `stirling sweep`",
                f.display()
            )
        })?;
        parts.push(s);
    }
    let s = sweep::merge(parts)?;
    files::prepare_dir(&a.out, &OUTPUTS, a.force, "--out")?;
    write(&a.out, &s, a.force)
}

fn progress_bar(n: u64) -> ProgressBar {
    let bar = ProgressBar::new(n);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} sweep [{bar:40}] {pos}/{len} points ({elapsed}, eta {eta})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// The CSV, the JSON, a summary line and, over two parameters of a whole grid, the map.
fn write(dir: &Path, s: &Sweep, force: bool) -> anyhow::Result<()> {
    let csv = dir.join("sweep.csv");
    files::write_text(&csv, &table::csv(s), force, "--out")?;
    let json = dir.join("sweep.json");
    files::write_text(&json, &serde_json::to_string_pretty(s)?, force, "--out")?;
    if s.axes.len() == 2 && s.shard.is_none() {
        let svg = dir.join("sweep_map.svg");
        draw_map(&svg, s)?;
        files::wrote(&svg);
    }
    let count = |o: Outcome| s.points.iter().filter(|r| r.outcome == o).count();
    common::print(&format!(
        "{} points: {} run, {} stable at rest, {} unstable without a cycle, {} unstable (poles only), {} failed\n",
        s.points.len(),
        count(Outcome::Runs),
        count(Outcome::Stable),
        count(Outcome::UnstableNoCycle),
        count(Outcome::Unstable),
        count(Outcome::Failed)
    ))?;
    Ok(())
}

/// The map of a two-axis sweep.
fn draw_map(path: &Path, s: &Sweep) -> anyhow::Result<()> {
    let (ax, ay) = (&s.axes[0], &s.axes[1]);
    let ny = ay.values.len();
    let cells: Vec<Vec<Cell>> = (0..ax.values.len())
        .map(|i| {
            (0..ny)
                .map(|j| {
                    let r = &s.points[i * ny + j];
                    match (r.outcome, r.power_w) {
                        (Outcome::Runs, Some(w)) => Cell::Runs(w),
                        (Outcome::Stable, _) => Cell::Stable,
                        (Outcome::Failed, _) => Cell::Failed,
                        _ => Cell::UnstableNoCycle,
                    }
                })
                .collect()
        })
        .collect();
    let title = format!("{} (n = {}): power of the limit cycle", s.model, s.n);
    let unit = |k: usize| s.units.get(k).map_or("-", |u| u.as_str());
    let (xl, yl) = (
        axes::label(&ax.name, unit(0)),
        axes::label(&ay.name, unit(1)),
    );
    let map = Map {
        xs: &ax.values,
        ys: &ay.values,
        x_label: &xl,
        y_label: &yl,
        cells: &cells,
    };
    sweep_map::sweep_map(path, &title, &map)?;
    Ok(())
}
