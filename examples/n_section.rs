//! The main job: `nsection` with `n` regenerator sections on the embedded default engine.
//!
//! ```text
//! cargo run --release --example n_section -- 10 [--json] [--out DIR] [--t-max SECONDS]
//! ```
//!
//! Prints the states, the equilibrium, the leading closed-loop poles, the gain and phase
//! margins of the loop broken at the pressure force, the limit cycle (frequency,
//! amplitudes, phase, cycle work, indicated power, Floquet multipliers) and the time each
//! stage took; writes SVG plots (pole map, Bode, start-up response, PV diagrams) to the
//! folder it names (default `out/n_section_n<N>`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;
use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::linear::{self, LinearOptions, Linearization};
use stirling::models::plot;
use stirling::models::sim::{self, LimitCycleReport, SimOptions, SimSummary};

/// Command-line options.
struct Args {
    n: usize,
    json: bool,
    out: PathBuf,
    t_max: f64,
}

fn usage() -> String {
    "usage: n_section [N] [--json] [--out DIR] [--t-max SECONDS]\n  N: regenerator sections (default 10)".to_string()
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        n: 10,
        json: false,
        out: PathBuf::new(),
        t_max: 8.0,
    };
    let mut it = std::env::args().skip(1);
    let mut out = None;
    while let Some(a) = it.next() {
        match a.as_str() {
            "--json" => args.json = true,
            "--out" => out = Some(PathBuf::from(it.next().ok_or("--out needs a folder")?)),
            "--t-max" => args.t_max = number(it.next(), "--t-max")?,
            "-h" | "--help" => return Err(usage()),
            s => {
                args.n = s.parse().map_err(|_| {
                    format!("expected a number of sections, found `{s}`\n{}", usage())
                })?
            }
        }
    }
    if args.n == 0 {
        return Err("N must be at least 1".into());
    }
    args.out = out.unwrap_or_else(|| PathBuf::from(format!("out/n_section_n{}", args.n)));
    Ok(args)
}

fn number(s: Option<String>, flag: &str) -> Result<f64, String> {
    s.and_then(|v| v.parse().ok())
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or(format!("{flag} needs a positive number"))
}

/// Wall time of each stage (s).
#[derive(Serialize, Default)]
struct Timings {
    linearize_s: f64,
    limit_cycle_s: f64,
    plots_s: f64,
}

/// Everything the example reports (`--json`).
#[derive(Serialize)]
struct Summary {
    model: String,
    n: usize,
    closure: String,
    n_states: usize,
    state_names: Vec<String>,
    linear: linear::LinearReport,
    cycle: SimSummary,
    plots: Vec<String>,
    timings: Timings,
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
    let model = NSection::new(args.n, Closure::Full)?;
    let p = model.default_params();
    let mut timings = Timings::default();
    let t0 = Instant::now();
    let lin = linear::linearize(&model, &p, &LinearOptions::default())?;
    timings.linearize_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let lc = limit_cycle(&model, &p, &lin, args.t_max, !args.json)?;
    timings.limit_cycle_s = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let plots = write_plots(&model, &p, &lin, &lc, &args.out)?;
    timings.plots_s = t0.elapsed().as_secs_f64();
    let summary = Summary {
        model: model.name().into(),
        n: model.n(),
        closure: model.closure().to_string(),
        n_states: model.n_states(),
        state_names: model.state_names(),
        linear: lin.report(&model),
        cycle: SimSummary::from_run(&model, &lc.settled.trajectory).with_cycle(&lc),
        plots,
        timings,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        print_summary(&summary, &lin, &lc);
    }
    Ok(())
}

/// Start 1 mm off the equilibrium, grow, settle and shoot; a progress bar on stderr.
fn limit_cycle(
    model: &dyn Model,
    p: &[f64],
    lin: &Linearization,
    t_max: f64,
    bar: bool,
) -> Result<LimitCycleReport, sim::SimError> {
    let mut x0 = lin.dynamics.equilibrium.x.clone();
    x0[0] += 1e-3;
    let samples = sim::integrate::uniform_samples(t_max, 4000);
    let pb = indicatif::ProgressBar::new(1000);
    if !bar {
        pb.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    pb.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {elapsed}")
            .expect("valid template"),
    );
    pb.set_message("simulating to the limit cycle");
    let mut progress = |t: f64| pb.set_position((1000.0 * t / t_max) as u64);
    let lc = sim::limit_cycle(
        model,
        p,
        &x0,
        t_max,
        &samples,
        &SimOptions::default(),
        Some(&mut progress),
    );
    pb.finish_and_clear();
    lc
}

fn write_plots(
    model: &dyn Model,
    p: &[f64],
    lin: &Linearization,
    lc: &LimitCycleReport,
    out: &Path,
) -> Result<Vec<String>, Box<dyn std::error::Error>> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let title = format!("nsection n = {}", model.n());
    let files = [
        out.join("poles.svg"),
        out.join("bode.svg"),
        out.join("startup.svg"),
        out.join("pv.svg"),
    ];
    plot::poles::pole_map(&files[0], &title, &lin.dynamics.poles, &lin.open_loop.poles)?;
    // the same figure as `stirling linearize --plot`
    plot::bode::loop_bode(&files[1], &plot::bode::model_tag(model), lin)?;
    let tr = &lc.settled.trajectory;
    let pressures = pressure_channels(model);
    plot::timeseries::startup_svg(&files[2], &title, &tr.t, &tr.x, 0, 2, &pressures)?;
    let (names, loops, work) = pv_loops(model, p, lc);
    plot::pv::pv_svg(&files[3], &title, &names, &loops, &work)?;
    Ok(files.iter().map(|f| f.display().to_string()).collect())
}

/// The hot and cold pressures (first and last pressure states).
fn pressure_channels(model: &dyn Model) -> Vec<(String, usize)> {
    let states = model.states();
    let ps: Vec<usize> = (0..states.len())
        .filter(|&i| states[i].unit == "Pa")
        .collect();
    let mut out = vec![(states[ps[0]].name.clone(), ps[0])];
    if let Some(&last) = ps.last().filter(|&&l| l != ps[0]) {
        out.push((states[last].name.clone(), last));
    }
    out
}

/// `(V, P)` loops of the vessels whose volume changes, with their cycle work.
fn pv_loops(
    model: &dyn Model,
    p: &[f64],
    lc: &LimitCycleReport,
) -> (Vec<String>, Vec<Vec<(f64, f64)>>, Vec<f64>) {
    let names = model.vessel_names();
    let k = names.len();
    let loops = sim::work::pv_loops(model, p, &lc.orbit);
    // a loop needs both the volume and the pressure to change (not a section, not the fixed bounce space)
    let span = |l: &Vec<(f64, f64)>, f: fn(&(f64, f64)) -> f64| {
        let (lo, hi) = l
            .iter()
            .map(f)
            .fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
        hi - lo
    };
    let moving = |l: &Vec<(f64, f64)>| span(l, |q| q.0) > 1e-12 && span(l, |q| q.1) > 1e-6;
    let keep: Vec<usize> = (0..k).filter(|&i| moving(&loops[i])).collect();
    let work = keep
        .iter()
        .map(|&i| lc.work.per_vessel.get(i).copied().unwrap_or(0.0))
        .collect();
    (
        keep.iter().map(|&i| names[i].clone()).collect(),
        keep.iter().map(|&i| loops[i].clone()).collect(),
        work,
    )
}

fn print_summary(s: &Summary, lin: &Linearization, lc: &LimitCycleReport) {
    println!(
        "nsection, n = {} regenerator sections, closure {}: {} states",
        s.n, s.closure, s.n_states
    );
    println!("  states: {}", abbreviate(&s.state_names));
    let eq = &lin.dynamics.equilibrium;
    println!(
        "\nequilibrium (Newton, {} iterations, scaled residual {:.2e} 1/s)",
        eq.iterations, eq.scaled_residual
    );
    println!(
        "  x = {:.3e} m, y = {:.3e} m, P_hot = {:.1} Pa",
        eq.x[0], eq.x[2], eq.x[4]
    );
    println!("\nleading closed-loop poles (inventory mode removed)");
    println!(
        "  {:>12} {:>12} {:>10} {:>10} {:>9}",
        "re [1/s]", "im [rad/s]", "f [Hz]", "damping", ""
    );
    for pole in lin.dynamics.poles.iter().filter(|p| p.im >= 0.0).take(5) {
        let flag = if pole.rhp { "RHP" } else { "" };
        println!(
            "  {:>12.4} {:>12.4} {:>10.3} {:>10.4} {:>9}",
            pole.re, pole.im, pole.freq_hz, pole.damping_ratio, flag
        );
    }
    print_margins(lin);
    print_cycle(&s.cycle, lc);
    println!("\nplots: {}", s.plots.join(", "));
    let t = &s.timings;
    println!(
        "timings: linearize {:.3} s, limit cycle {:.3} s, plots {:.3} s",
        t.linearize_s, t.limit_cycle_s, t.plots_s
    );
}

fn print_margins(lin: &Linearization) {
    let m = &lin.margins;
    let opt = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
    println!("\nloop broken at `{}` (MATLAB `margin` selection): gain margin {} dB at {} rad/s, phase margin {} deg at {} rad/s",
        lin.open_loop.full.name, opt(m.gain_db), opt(m.phase_crossover_rad_s), opt(m.phase_deg), opt(m.gain_crossover_rad_s));
    let gains: Vec<String> = m
        .all_gain
        .iter()
        .map(|g| {
            format!(
                "{:.3} dB at {:.2} rad/s",
                g.gain_db, g.phase_crossover_rad_s
            )
        })
        .collect();
    let phases: Vec<String> = m
        .all_phase
        .iter()
        .map(|g| {
            format!(
                "{:.2} deg at {:.2} rad/s",
                g.phase_deg, g.gain_crossover_rad_s
            )
        })
        .collect();
    println!(
        "  all crossovers: gain {}; phase {}",
        gains.join(", "),
        phases.join(", ")
    );
    let rhp = lin.open_loop.poles.iter().filter(|p| p.rhp).count();
    println!("  open loop has {rhp} RHP poles; closed loop has {} (the engine runs because the closed loop is unstable)",
        lin.dynamics.poles.iter().filter(|p| p.rhp).count());
}

fn print_cycle(c: &SimSummary, lc: &LimitCycleReport) {
    let f = |v: Option<f64>| v.unwrap_or(f64::NAN);
    println!(
        "\nlimit cycle (settled at t = {:.3} s, shooting {} Newton iterations)",
        lc.settled.t, lc.cycle.iterations
    );
    println!("  frequency {:.4} Hz, displacer amplitude {:.3} mm, piston amplitude {:.3} mm, phase {:.2} deg",
        f(c.frequency_hz), 1e3 * f(c.x_amp), 1e3 * f(c.y_amp), f(c.phase_deg));
    println!(
        "  cycle work {:.4} J, indicated power {:.3} W",
        f(c.work_per_cycle_j),
        f(c.power_w)
    );
    if let Some(fl) = &c.floquet {
        let shown: Vec<String> = fl
            .iter()
            .take(4)
            .map(|z| format!("{:.5}{:+.5}i", z[0], z[1]))
            .collect();
        println!(
            "  Floquet multipliers (largest first): {}",
            shown.join(", ")
        );
    }
    println!(
        "  solver: {} steps, {} RHS calls, {} Jacobian calls",
        c.steps, c.rhs_calls, c.jacobian_calls
    );
}

fn abbreviate(names: &[String]) -> String {
    if names.len() <= 12 {
        return names.join(", ");
    }
    format!(
        "{}, ..., {} ({} in all)",
        names[..6].join(", "),
        names[names.len() - 3..].join(", "),
        names.len()
    )
}
