//! `stirling simulate`: a nonlinear run (BDF on the analytic Jacobian), optionally
//! refined to a limit cycle, with CSV, JSON summary and SVG plots.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use stirling_dsl::{Model, StateKind};
use stirling_models::sim::{self, SimOptions, SimSummary, Trajectory};

use crate::common::{self, files, ranges, ModelArgs};

/// The running figures and Schmidt's analysis of a kinematic engine's run.
mod kinematic;

/// The largest CSV `--out` writes (bytes).
const MAX_CSV_BYTES: f64 = 1e9;

/// Arguments of `stirling simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// End time (s, > 0); with --limit-cycle, the longest settling time
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::positive)]
    pub t_end: f64,
    /// Initial state, comma-separated, all states in the order `stirling info MODEL` lists
    #[arg(long, conflicts_with = "perturb", allow_hyphen_values = true)]
    pub x0: Option<String>,
    /// Start from equilibrium with the displacer displaced by X metres (default 5e-3)
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::finite)]
    pub perturb: Option<f64>,
    /// Starting value of a state by name, set after the rest state and the kick, e.g.
    /// --start omega=6.3: a push start of a kinematic engine's flywheel (rad/s; repeatable).
    /// A kinematic engine's run then reports its speed, indicated power and Schmidt's analysis
    #[arg(long, value_name = "STATE=VALUE", allow_hyphen_values = true, value_parser = ranges::state_value)]
    pub start: Vec<(String, f64)>,
    /// Number of output samples (2 to 1e6)
    #[arg(long, default_value_t = 2000, allow_negative_numbers = true, value_parser = ranges::samples)]
    pub samples: usize,
    /// Relative tolerance, in [1e-14, 0.1]
    #[arg(long, default_value_t = 1e-7, allow_negative_numbers = true, value_parser = ranges::tolerance)]
    pub rtol: f64,
    /// Scaled absolute tolerance, in [1e-14, 0.1] (default: --rtol)
    #[arg(long, allow_negative_numbers = true, value_parser = ranges::tolerance)]
    pub atol: Option<f64>,
    /// Write the sampled trajectory as CSV (folders created if missing)
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Overwrite an existing --out file and existing --plot figures
    #[arg(long)]
    pub force: bool,
    /// Print the summary as JSON
    #[arg(long)]
    pub json: bool,
    /// Write SVG plots (start-up response; PV diagrams with --limit-cycle) into this folder
    /// (created if missing)
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Run until periodic, refine by shooting, report the cycle
    #[arg(long)]
    pub limit_cycle: bool,
    /// Shooting route of --limit-cycle: auto (dense monodromy up to 400 states, the block route
    /// with the leading Floquet multipliers above), dense, block, krylov (stored stage factors:
    /// gigabytes at 2000 states), or none
    #[arg(long, value_enum, default_value_t = ShootingArg::Auto, requires = "limit_cycle")]
    pub shooting: ShootingArg,
}

/// `--shooting`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShootingArg {
    Auto,
    Dense,
    Block,
    Krylov,
    None,
}

impl From<ShootingArg> for sim::Shooting {
    fn from(a: ShootingArg) -> Self {
        match a {
            ShootingArg::Auto => sim::Shooting::Auto,
            ShootingArg::Dense => sim::Shooting::Dense,
            ShootingArg::Block => sim::Shooting::Block,
            ShootingArg::Krylov => sim::Shooting::Krylov,
            ShootingArg::None => sim::Shooting::Never,
        }
    }
}

pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    let (model, p) = args.model.load()?;
    let model = model.as_ref();
    check_outputs(args, model)?;
    common::unique("--start", &args.start, |(c, _)| c.clone())?;
    let mut x0 = initial_state(model, &p, args)?;
    apply_start(model, &mut x0, &args.start)?;
    let bar = progress_bar();
    let t_end = args.t_end;
    let mut progress = |t: f64| {
        bar.set_position((1000.0 * t / t_end) as u64);
        bar.set_message(format!("{t:.4}"));
    };
    let (traj, mut summary, lc) = simulate(model, &p, &x0, args, &mut progress)?;
    bar.finish_and_clear();
    if lc.is_none() {
        kinematic::add_running(model, &p, &traj, &mut summary);
    }
    if let Some(out) = &args.out {
        write_csv(out, args.force, model, &traj)?;
    }
    if let Some(dir) = &args.plot {
        plots(dir, model, &p, &traj, lc.as_ref())?;
    }
    if args.json {
        common::print_json(&summary)
    } else {
        Ok(print_summary(&mut common::stdout(), &summary)?)
    }
}

/// The progress bar of a run, in thousandths of `t_end`.
fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{spinner} simulating [{bar:40}] t = {msg} s ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

/// The run: a checked integration over `t_end`, or with `--limit-cycle` the refined cycle.
fn simulate(
    model: &dyn Model,
    p: &[f64],
    x0: &[f64],
    args: &SimulateArgs,
    progress: &mut dyn FnMut(f64),
) -> anyhow::Result<(Trajectory, SimSummary, Option<sim::LimitCycleReport>)> {
    // `--samples` counts the rows: the first at 0, the last at t_end
    let samples = sim::uniform_samples(args.t_end, args.samples - 1);
    let opts = SimOptions {
        rtol: args.rtol,
        atol: args.atol.unwrap_or(args.rtol),
        ..Default::default()
    };
    if args.limit_cycle {
        // a flywheel's angle grows by 2 pi a revolution: no closed orbit of every state to shoot
        if let Some(s) = model.states().iter().find(|s| s.unit == "rad") {
            anyhow::bail!(
                "limit cycle of `{}`: `--limit-cycle` shoots a closed orbit of every state, but the flywheel's angle `{}` grows by 2 pi a revolution (a kinematic engine, docs/physics.md section 12); run without it from a push (`--x0` with the speed > 0) and read the speed from the trajectory",
                model.name(),
                s.name
            );
        }
        let shooting = args.shooting.into();
        let lc = sim::limit_cycle_with(
            model,
            p,
            x0,
            args.t_end,
            &samples,
            &opts,
            shooting,
            Some(progress),
        )
        .map_err(|e| match common::rest::stable_at_rest(model, p) {
            // its "run longer" would not help
            Some(re) => anyhow::anyhow!("no limit cycle: {}", common::rest::no_cycle(re)),
            None => e.into(),
        })
        .with_context(|| format!("limit cycle of `{}`", model.name()))?;
        common::rest::check_cycle(model, p, &lc)
            .with_context(|| format!("limit cycle of `{}`", model.name()))?;
        let tr = lc.settled.trajectory.clone();
        let s = SimSummary::from_run(model, &tr).with_cycle(&lc);
        return Ok((tr, s, Some(lc)));
    }
    let checker = sim::PhysicalCheck::new(model, p);
    let check = |t: f64, x: &[f64]| checker.check(t, x);
    let hooks = sim::Hooks {
        check: Some(&check),
        progress: Some(progress),
        ..Default::default()
    };
    let tr = sim::integrate(
        &sim::ModelSystem { model, p },
        x0,
        args.t_end,
        &samples,
        &opts,
        hooks,
    )
    .with_context(|| format!("simulation of `{}`", model.name()))?;
    let s = SimSummary::from_run(model, &tr);
    Ok((tr, s, None))
}

/// The figures `--plot` writes.
fn figures(args: &SimulateArgs) -> &'static [&'static str] {
    if args.limit_cycle {
        &["startup.svg", "pv.svg"]
    } else {
        &["startup.svg"]
    }
}

/// Refuse, before the run, outputs that exist (without --force) or a CSV too large to use.
fn check_outputs(args: &SimulateArgs, model: &dyn Model) -> anyhow::Result<()> {
    if let Some(out) = &args.out {
        let columns = model.n_states() + 1;
        // `{:.10e}` and a separator: 18 bytes a value at most
        let bytes = args.samples as f64 * columns as f64 * 18.0;
        if bytes > MAX_CSV_BYTES {
            bail!(
                "--out {}: {} samples of {columns} columns would write about {:.1} GB (the limit is {:.0} GB); lower --samples",
                out.display(),
                args.samples,
                bytes / 1e9,
                MAX_CSV_BYTES / 1e9
            );
        }
        files::prepare_file(out, args.force, "--out")?;
    }
    if let Some(dir) = &args.plot {
        files::prepare_dir(dir, figures(args), args.force, "--plot")?;
    }
    Ok(())
}

fn initial_state(model: &dyn Model, p: &[f64], args: &SimulateArgs) -> anyhow::Result<Vec<f64>> {
    let n = model.n_states();
    if let Some(s) = &args.x0 {
        let x: Vec<f64> = s
            .split(',')
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .with_context(|| format!("--x0: `{v}` is not a finite number"))
            })
            .collect::<Result<_, _>>()?;
        if x.len() != n {
            bail!(
                "--x0 has {} values; `{}` has {} states: {} (see `stirling info {}`)",
                x.len(),
                model.name(),
                n,
                model.state_names().join(", "),
                model.name()
            );
        }
        return Ok(x);
    }
    let mut x = vec![0.0; n];
    model.equilibrium_guess(p, &mut x);
    let ix = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(0))
        .context("the model has no displacer position")?;
    x[ix] += args.perturb.unwrap_or(5e-3);
    Ok(x)
}

/// `--start NAME=VALUE`: each named state set to its value.
fn apply_start(model: &dyn Model, x: &mut [f64], start: &[(String, f64)]) -> anyhow::Result<()> {
    let names = model.state_names();
    for (name, v) in start {
        let Some(i) = names.iter().position(|n| n == name) else {
            bail!(
                "--start {name}={v}: `{}` has no state `{name}`; its states: {}",
                model.name(),
                names.join(", ")
            );
        };
        x[i] = *v;
    }
    Ok(())
}

fn write_csv(path: &Path, force: bool, model: &dyn Model, tr: &Trajectory) -> anyhow::Result<()> {
    let mut f = files::create(path, force, "--out")?;
    let mut rows = || -> std::io::Result<()> {
        writeln!(f, "t,{}", model.state_names().join(","))?;
        for (t, x) in tr.t.iter().zip(&tr.x) {
            let row: Vec<String> = x.iter().map(|v| format!("{v:.10e}")).collect();
            writeln!(f, "{t:.10e},{}", row.join(","))?;
        }
        f.flush()
    };
    rows().with_context(|| format!("cannot write {}", path.display()))?;
    f.done()?;
    files::wrote(path);
    Ok(())
}

fn plots(
    dir: &Path,
    model: &dyn Model,
    p: &[f64],
    tr: &Trajectory,
    lc: Option<&sim::LimitCycleReport>,
) -> anyhow::Result<()> {
    let states = model.states();
    let find = |k: StateKind| states.iter().position(|s| s.kind == k);
    let (ix, iy) = (
        find(StateKind::Position(0)).unwrap_or(0),
        find(StateKind::Position(1)).unwrap_or(0),
    );
    let pressures: Vec<(String, usize)> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s.kind, StateKind::Pressure(_)))
        .map(|(i, s)| (s.name.clone(), i))
        .collect();
    let title = format!("{} (n = {})", model.name(), model.n());
    let startup = dir.join("startup.svg");
    stirling_models::plot::timeseries::startup_svg(
        &startup, &title, &tr.t, &tr.x, ix, iy, &pressures,
    )
    .map_err(anyhow::Error::msg)?;
    files::wrote(&startup);
    if let Some(lc) = lc {
        let loops = sim::work::pv_loops(model, p, &lc.orbit);
        let pv = dir.join("pv.svg");
        stirling_models::plot::pv::pv_svg(
            &pv,
            &title,
            &lc.work.vessels,
            &loops,
            &lc.work.per_vessel,
        )
        .map_err(anyhow::Error::msg)?;
        files::wrote(&pv);
    }
    Ok(())
}

fn print_summary(o: &mut impl Write, s: &SimSummary) -> std::io::Result<()> {
    writeln!(
        o,
        "model {} (n = {}, closure {}, {} states), t_end = {} s",
        s.model, s.n, s.closure, s.n_states, s.t_end
    )?;
    if let (Some(f), Some(xa), Some(ya), Some(ph)) = (s.frequency_hz, s.x_amp, s.y_amp, s.phase_deg)
    {
        writeln!(o, "limit cycle: f = {f:.4} Hz ({:.2} rad/s), x_amp = {:.3} mm, y_amp = {:.3} mm, phase(x - y) = {ph:.2} deg", f * std::f64::consts::TAU, 1e3 * xa, 1e3 * ya)?;
        if let Some(pa) = &s.p_amp {
            let pa: Vec<String> = pa.iter().map(|v| format!("{:.1}", v)).collect();
            writeln!(o, "pressure amplitudes (Pa): {}", pa.join(", "))?;
        }
        if let (Some(w), Some(pw)) = (s.work_per_cycle_j, s.power_w) {
            writeln!(o, "work per cycle {w:.5} J, indicated power {pw:.4} W")?;
        }
        if let Some(v) = &s.work_per_vessel_j {
            for (name, w) in v {
                writeln!(o, "  {name:>12}: {w:+.5} J")?;
            }
        }
        if let Some(fl) = &s.floquet {
            let fl: Vec<String> = fl
                .iter()
                .take(6)
                .map(|[re, im]| {
                    if *im == 0.0 {
                        format!("{re:.6}")
                    } else {
                        format!("{re:.6}{im:+.6}i")
                    }
                })
                .collect();
            writeln!(o, "Floquet multipliers (largest): {}", fl.join(", "))?;
        }
        if let Some(route) = s.shooting {
            let how = match route {
                sim::ShootingRoute::Dense => "dense monodromy (all multipliers)",
                sim::ShootingRoute::Krylov => {
                    "Newton-Krylov (GMRES), leading multipliers by Arnoldi"
                }
                sim::ShootingRoute::Block => {
                    "Newton on a low-rank monodromy, leading multipliers by block Arnoldi"
                }
                sim::ShootingRoute::Settled => "none (the settled cycle as measured)",
            };
            writeln!(o, "shooting: {how}")?;
        }
    } else {
        let x: Vec<String> = s.final_state.iter().map(|v| format!("{v:.6e}")).collect();
        writeln!(o, "final state: {}", x.join(", "))?;
        kinematic::print(o, s)?;
    }
    writeln!(
        o,
        "solver: {} steps, {} RHS calls, {} Jacobian calls, {} LU factorizations",
        s.steps, s.rhs_calls, s.jacobian_calls, s.lu_factorizations
    )?;
    Ok(())
}
