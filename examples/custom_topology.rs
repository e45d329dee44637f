//! A free-piston engine that is not in the seed's family, declared in user code with the
//! public `stirling_model!` DSL only, and run through every analysis.
//!
//! The engine is the default B-10B-like engine (docs/physics.md section 8) with two changes:
//! - **closed bounce space**: the gas under the piston is a control volume `bounce` with its
//!   own state `P_bounce` and a heat port to a wall at `Tb` (a gas spring with hysteresis
//!   loss, docs/physics.md section 9), instead of a space held at the fixed pressure `Pb`;
//! - **linear alternator** on the power piston: an extra force `-c_alt w`; its power
//!   `c_alt w^2` is the electric output. The piston's own damping `bp` is friction only.
//!
//! The working gas is the `nsection` layout (hot space, `n` regenerator sections, cold space):
//! the model extends the family's `nsection_engine` (docs/custom-topologies.md, "Composition").
//!
//! Run: `cargo run --release --example custom_topology -- --n 4 --out target/custom_topology`
//! (`--json` prints a machine-readable summary; `--t-max` bounds the settling run).
//!
//! Printed: equilibrium, dynamic poles, the loop broken at the piston force with its margins,
//! the limit cycle (frequency, strokes, phase, Floquet multipliers), the work per vessel,
//! indicated and electric power; written: `poles.svg`, `bode.svg`, `startup.svg`, `pv.svg`.

use std::error::Error;
use std::path::{Path, PathBuf};

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::linear::{self, LinearOptions, Linearization};
use stirling::models::plot;
use stirling::models::sim::{self, LimitCycleReport, SimOptions, SimSummary};
use stirling::stirling_model;

stirling_model! {
    /// Default engine with a closed, heat-exchanging bounce space and a linear alternator:
    /// the family's `nsection` engine (`stirling::models::nsection_engine`) extended. A base
    /// (`alternator_engine!`), so that the engine and its augmented member below share it.
    base alternator_engine extends stirling::models::nsection_engine {
        params {
            /// bounce-space volume at rest (closed crankcase)
            Vb0: 2.0e-3 "m^3",
            /// bounce-space wall temperature
            Tb: 300.0 "K",
            /// alternator load: force -c_alt w on the piston, electric power c_alt w^2
            c_alt: 6.0 "N s/m",
            /// alternator's motor constant: its voltage is Kv w (c_alt = Kv^2 / R_load)
            Kv: 25.0 "V s/m",
            /// bounce-space wall area
            Awb: 0.06 "m^2",
            /// bounce-space heat-transfer coefficient
            hb: 20.0 "W/(m^2 K)",
        }
        replace params {
            /// power-piston friction (the load is the alternator's)
            bp: 1.9083 "N s/m",
        }
        modify body piston { force: -c_alt * w }
        // the closed bounce space: same faces as the seed's fixed-pressure space, but a gas
        // volume of its own (no mass-flow link, so its mass is a constant). Removed and added
        // rather than replaced, so that it comes last among the CVs (`replace cv bounce {..}`
        // would keep the space's place, first).
        remove space bounce;
        remove param Pb;
        cv bounce {
            volume: Vb0,
            faces { displacer: Ar, piston: A - Ar },
            port wall { h: hb, area: Awb, wall: Tb },
        }
        // a transducer in the bounce space, besides the family's `p`, `p_hot`, `x`, `y`
        sensor p_bounce: P_bounce "Pa";
        // expressions of states and parameters: a differential transducer across the
        // piston, and the alternator's voltage
        sensor dp: P_cold - P_bounce "Pa";
        sensor emf: Kv * w "V";
    }
}

stirling_model! {
    /// The alternator engine (`alternator_engine`).
    pub model AlternatorEngine extends alternator_engine {
        name "alternator_engine";
    }
}

stirling_model! {
    /// The alternator engine with Coulomb friction on both bodies, `-Fc tanh(v / v_eps)`, at
    /// its null: the augmented member the diagnosis tests the effect with. Each `effect` item
    /// names where it acts; the macro adds the force term and its parameters at their null
    /// (`Fc_displacer = Fc_piston = 0`, `v_eps`), and the diagnosis offers `coulomb` with
    /// those parameters for this engine.
    pub model AlternatorFx extends alternator_engine {
        name "alternator_engine_fx";
        effect coulomb on displacer;
        effect coulomb on piston;
    }
}

/// Command-line settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Args {
    /// Regenerator sections.
    pub n: usize,
    /// Folder for the SVG figures (none: no figures).
    pub out: Option<PathBuf>,
    /// Print JSON instead of text.
    pub json: bool,
    /// Longest settling run (s).
    pub t_max: f64,
    /// Print anything at all (the tests run quietly).
    pub quiet: bool,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            n: 2,
            out: Some(PathBuf::from("target/custom_topology")),
            json: false,
            t_max: 20.0,
            quiet: false,
        }
    }
}

const USAGE: &str =
    "usage: custom_topology [--n N] [--out DIR | --no-plots] [--json] [--t-max SECONDS]";

/// Parse `--n N`, `--out DIR`, `--no-plots`, `--json`, `--t-max T`.
pub fn parse_args<I: IntoIterator<Item = String>>(args: I) -> Result<Args, String> {
    let mut a = Args::default();
    let mut it = args.into_iter();
    while let Some(flag) = it.next() {
        let mut value = |name: &str| {
            it.next()
                .ok_or_else(|| format!("{name} needs a value\n{USAGE}"))
        };
        match flag.as_str() {
            "--n" => {
                a.n = value("--n")?
                    .parse()
                    .map_err(|e| format!("--n: {e}\n{USAGE}"))?
            }
            "--out" => a.out = Some(PathBuf::from(value("--out")?)),
            "--no-plots" => a.out = None,
            "--json" => a.json = true,
            "--t-max" => {
                a.t_max = value("--t-max")?
                    .parse()
                    .map_err(|e| format!("--t-max: {e}\n{USAGE}"))?
            }
            "-h" | "--help" => return Err(USAGE.to_string()),
            other => return Err(format!("unknown argument `{other}`\n{USAGE}")),
        }
    }
    if a.n == 0 {
        return Err(format!("--n must be at least 1\n{USAGE}"));
    }
    Ok(a)
}

/// What a run found.
pub struct Summary {
    pub model: AlternatorEngine,
    pub p: Vec<f64>,
    pub linear: Linearization,
    pub cycle: LimitCycleReport,
    /// Mean alternator power `c_alt <w^2>` over the cycle (W).
    pub electric_power_w: f64,
    /// Indicated power `W f` (W).
    pub indicated_power_w: f64,
    /// Figures written.
    pub files: Vec<PathBuf>,
}

/// Start: equilibrium with the displacer displaced by 5 mm.
pub fn perturbed(model: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; model.n_states()];
    model.equilibrium_guess(p, &mut x);
    let ix = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Position(0))
        .expect("displacer");
    x[ix] += 5e-3;
    x
}

/// Mean of `c_alt w^2` over uniform orbit samples (last = first).
pub fn electric_power(model: &dyn Model, p: &[f64], orbit: &[Vec<f64>]) -> f64 {
    let iw = model
        .states()
        .iter()
        .position(|s| s.kind == StateKind::Velocity(1))
        .expect("piston velocity");
    let c_alt = p[model.param_index("c_alt").expect("c_alt")];
    let k = orbit.len().saturating_sub(1).max(1);
    orbit
        .iter()
        .take(k)
        .map(|x| c_alt * x[iw] * x[iw])
        .sum::<f64>()
        / k as f64
}

/// Build the model, run the analyses, write the figures.
pub fn run(args: &Args) -> Result<Summary, Box<dyn Error>> {
    let model = AlternatorEngine::new(args.n, Closure::Full)?;
    let p = model.default_params();
    let lin = linear::linearize(&model, &p, &LinearOptions::default())?;
    let x0 = perturbed(&model, &p);
    let samples = sim::uniform_samples(args.t_max.min(1.0), 2000);
    let cycle = sim::limit_cycle(
        &model,
        &p,
        &x0,
        args.t_max,
        &samples,
        &SimOptions::default(),
        None,
    )?;
    let electric_power_w = electric_power(&model, &p, &cycle.orbit);
    let indicated_power_w = sim::indicated_power(cycle.work.total, cycle.figures.frequency_hz);
    let files = match &args.out {
        Some(dir) => figures(dir, &model, &p, &lin, &cycle)?,
        None => Vec::new(),
    };
    Ok(Summary {
        model,
        p,
        linear: lin,
        cycle,
        electric_power_w,
        indicated_power_w,
        files,
    })
}

fn figures(
    dir: &Path,
    model: &dyn Model,
    p: &[f64],
    lin: &Linearization,
    lc: &LimitCycleReport,
) -> Result<Vec<PathBuf>, Box<dyn Error>> {
    std::fs::create_dir_all(dir)?;
    let title = format!("{} (n = {})", model.name(), model.n());
    let states = model.states();
    let find = |k: StateKind| states.iter().position(|s| s.kind == k).unwrap_or(0);
    let pressures: Vec<(String, usize)> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s.kind, StateKind::Pressure(_)))
        .map(|(i, s)| (s.name.clone(), i))
        .collect();
    let files = [
        dir.join("poles.svg"),
        dir.join("bode.svg"),
        dir.join("startup.svg"),
        dir.join("pv.svg"),
    ];
    plot::poles::pole_map(&files[0], &title, &lin.dynamics.poles, &lin.open_loop.poles)?;
    plot::bode::loop_bode(&files[1], &plot::bode::model_tag(model), lin)?;
    let tr = &lc.settled.trajectory;
    plot::timeseries::startup_svg(
        &files[2],
        &title,
        &tr.t,
        &tr.x,
        find(StateKind::Position(0)),
        find(StateKind::Position(1)),
        &pressures,
    )?;
    let loops = stirling::models::sim::work::pv_loops(model, p, &lc.orbit);
    plot::pv::pv_svg(
        &files[3],
        &title,
        &lc.work.vessels,
        &loops,
        &lc.work.per_vessel,
    )?;
    Ok(files.to_vec())
}

/// The text report.
pub fn print(s: &Summary) {
    let m = &s.model;
    let lin = &s.linear;
    let eq = &lin.dynamics.equilibrium;
    println!(
        "model {} (n = {}, closure {}, {} states)",
        m.name(),
        m.n(),
        m.closure(),
        m.n_states()
    );
    println!(
        "equilibrium: {} Newton iterations, scaled residual {:.2e} 1/s",
        eq.iterations, eq.scaled_residual
    );
    for (name, v) in m.state_names().iter().zip(&eq.x) {
        println!("  {name:>12} = {v:.6e}");
    }
    if let Some(inv) = &lin.dynamics.reduction.inventory {
        println!(
            "inventory mode: eigenvalue {:.2e} 1/s, conservation defect {:.2e}",
            inv.eigenvalue, inv.conservation_defect
        );
    }
    println!("dynamic poles (1/s):");
    for pole in &lin.dynamics.poles {
        println!(
            "  {:>12.4} {:+12.4}j  ({:7.3} Hz, zeta {:+.4}){}",
            pole.re,
            pole.im,
            pole.freq_hz,
            pole.damping_ratio,
            if pole.rhp { "  unstable" } else { "" }
        );
    }
    let mg = &lin.margins;
    let fmt = |v: Option<f64>, unit: &str| {
        v.map(|v| format!("{v:.3} {unit}"))
            .unwrap_or_else(|| "none".into())
    };
    println!(
        "loop broken at `{}` ({}):",
        lin.open_loop.full.name, lin.open_loop.full.unit
    );
    println!(
        "  Gm = {} at {}, Pm = {} at {}",
        fmt(mg.gain_db, "dB"),
        fmt(mg.phase_crossover_rad_s, "rad/s"),
        fmt(mg.phase_deg, "deg"),
        fmt(mg.gain_crossover_rad_s, "rad/s")
    );
    let lc = &s.cycle;
    let f = &lc.figures;
    println!(
        "limit cycle (settled at t = {:.3} s, shooting {} iterations, residual {:.2e}):",
        lc.settled.t, lc.cycle.iterations, lc.cycle.residual
    );
    println!(
        "  f = {:.4} Hz ({:.3} rad/s), x_amp = {:.3} mm, y_amp = {:.3} mm, phase x-y = {:.2} deg",
        f.frequency_hz,
        2.0 * std::f64::consts::PI * f.frequency_hz,
        1e3 * f.x_amp,
        1e3 * f.y_amp,
        f.phase_deg
    );
    let names = m.vessel_names();
    let pa: Vec<String> = names
        .iter()
        .zip(&f.p_amp)
        .map(|(n, a)| format!("{n} {:.3} kPa", 1e-3 * a))
        .collect();
    println!("  pressure amplitudes: {}", pa.join(", "));
    let moduli: Vec<String> = lc
        .cycle
        .floquet
        .iter()
        .map(|(re, im)| format!("{:.4}", re.hypot(*im)))
        .collect();
    println!("  Floquet |mu|: {}", moduli.join(" "));
    println!("work per cycle (closed-integral P dV, J):");
    for (n, w) in lc.work.vessels.iter().zip(&lc.work.per_vessel) {
        println!("  {n:>12} {w:+.5e}");
    }
    println!("  {:>12} {:+.5e}", "total", lc.work.total);
    println!(
        "indicated power {:.4} W, electric (alternator) power {:.4} W",
        s.indicated_power_w, s.electric_power_w
    );
    for file in &s.files {
        println!("wrote {}", file.display());
    }
}

/// The `--json` report: the linear report and the limit-cycle summary.
pub fn json(s: &Summary) -> serde_json::Value {
    let lc = SimSummary::from_run(&s.model, &s.cycle.settled.trajectory).with_cycle(&s.cycle);
    serde_json::json!({
        "linear": serde_json::to_value(s.linear.report(&s.model)).unwrap_or_default(),
        "limit_cycle": serde_json::to_value(&lc).unwrap_or_default(),
        "indicated_power_w": s.indicated_power_w,
        "electric_power_w": s.electric_power_w,
        "files": s.files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
    })
}

#[allow(dead_code)]
fn main() {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    match run(&args) {
        Ok(s) if args.json => println!(
            "{}",
            serde_json::to_string_pretty(&json(&s)).unwrap_or_default()
        ),
        Ok(s) => print(&s),
        Err(e) => {
            eprintln!("custom_topology: {e}");
            std::process::exit(1);
        }
    }
}
