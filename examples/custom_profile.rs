//! An array of control volumes with a user-chosen wall-temperature profile, at a section
//! count `n` chosen on the command line.
//!
//! The seed's `nsection` regenerator has a linear wall profile from `Th` to `Tk`. Here the
//! user declares the profile as a power law of the distance from the cold end,
//!
//! `Tw_j = Tk + (Th - Tk) ((n - j - 1/2) / n)^kappa`,   j = 0 .. n-1 (section 0 at the hot end),
//!
//! with the exponent `kappa` a model parameter: `kappa = 1` is the seed's linear profile (and
//! the model then reproduces `nsection` exactly), `kappa = 2` a profile that sags toward `Tk`
//! (a regenerator whose cold part is over-cooled). Everything else is the family's `nsection`
//! engine, which the model extends (docs/custom-topologies.md, "Composition").
//!
//! Run: `cargo run --release --example custom_profile -- --n 10 --kappa 2`
//! (`--json` for a machine-readable summary).
//!
//! Printed: the wall and rest gas temperatures per section, the equilibrium, the dynamic poles
//! and margins for the chosen `kappa`, next to the linear profile (`kappa = 1`).

use std::error::Error;

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::linear::{self, LinearOptions, Linearization};
use stirling::stirling_model;

stirling_model! {
    /// Hot space, `n` regenerator sections with a power-law wall profile, cold space: the
    /// family's `nsection` engine (`stirling::models::nsection_engine`) with its regenerator
    /// replaced and one parameter added.
    pub model ProfiledRegenerator extends stirling::models::nsection_engine {
        name "profiled_regenerator";
        params {
            /// exponent of the regenerator wall profile (1: linear)
            kappa: 2.0 "-",
        }
        // the user's profile: section j (0 at the hot end) at its mid-point
        replace cv regen[n] {
            volume: Vr / n,
            port wall { h: hr, area: Awr / n, wall: Tk + (Th - Tk) * ((n - j - 0.5) / n).powf(kappa) },
        }
    }
}

/// Command-line settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Args {
    /// Regenerator sections (run time).
    pub n: usize,
    /// Profile exponent.
    pub kappa: f64,
    /// Print JSON instead of text.
    pub json: bool,
}

impl Default for Args {
    fn default() -> Self {
        Self {
            n: 8,
            kappa: 2.0,
            json: false,
        }
    }
}

const USAGE: &str = "usage: custom_profile [--n N] [--kappa K] [--json]";

/// Parse `--n N`, `--kappa K`, `--json`.
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
            "--kappa" => {
                a.kappa = value("--kappa")?
                    .parse()
                    .map_err(|e| format!("--kappa: {e}\n{USAGE}"))?
            }
            "--json" => a.json = true,
            "-h" | "--help" => return Err(USAGE.to_string()),
            other => return Err(format!("unknown argument `{other}`\n{USAGE}")),
        }
    }
    if a.n == 0 {
        return Err(format!("--n must be at least 1\n{USAGE}"));
    }
    if !(a.kappa > 0.0) {
        return Err(format!("--kappa must be positive\n{USAGE}"));
    }
    Ok(a)
}

/// The analysis at one exponent.
pub struct Case {
    pub kappa: f64,
    pub p: Vec<f64>,
    /// Declared wall temperature of each regenerator section (K), hot end first.
    pub wall: Vec<f64>,
    /// Gas temperature of every CV element at the equilibrium (K): hot, sections, cold.
    pub gas: Vec<f64>,
    pub linear: Linearization,
}

/// What a run found: the chosen profile and the linear one.
pub struct Summary {
    pub model: ProfiledRegenerator,
    pub chosen: Case,
    pub linear_profile: Case,
}

/// The profile as declared, evaluated in Rust (for printing and for the tests).
pub fn wall_profile(th: f64, tk: f64, kappa: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| tk + (th - tk) * ((n as f64 - j as f64 - 0.5) / n as f64).powf(kappa))
        .collect()
}

/// Equilibrium, poles and margins of `model` at exponent `kappa`.
pub fn case(model: &ProfiledRegenerator, kappa: f64) -> Result<Case, Box<dyn Error>> {
    let mut p = model.default_params();
    let ik = model.param_index("kappa").ok_or("no parameter kappa")?;
    p[ik] = kappa;
    let (th, tk) = (
        p[model.param_index("Th").ok_or("Th")?],
        p[model.param_index("Tk").ok_or("Tk")?],
    );
    let linear = linear::linearize(model, &p, &LinearOptions::default())?;
    let n_cv = model
        .states()
        .iter()
        .filter(|s| matches!(s.kind, StateKind::Pressure(_)))
        .count();
    let mut gas = vec![0.0; n_cv];
    model.temperatures(&p, &linear.dynamics.equilibrium.x, &mut gas);
    Ok(Case {
        kappa,
        wall: wall_profile(th, tk, kappa, model.n()),
        gas,
        p,
        linear,
    })
}

/// Build at `n` and analyse the chosen and the linear profile.
pub fn run(args: &Args) -> Result<Summary, Box<dyn Error>> {
    let model = ProfiledRegenerator::new(args.n, Closure::Full)?;
    let chosen = case(&model, args.kappa)?;
    let linear_profile = case(&model, 1.0)?;
    Ok(Summary {
        model,
        chosen,
        linear_profile,
    })
}

fn print_case(c: &Case) {
    let eq = &c.linear.dynamics.equilibrium;
    println!(
        "kappa = {}: equilibrium in {} Newton iterations (scaled residual {:.2e} 1/s)",
        c.kappa, eq.iterations, eq.scaled_residual
    );
    println!("  {:>8} {:>10} {:>10}", "section", "wall (K)", "gas (K)");
    for (j, (tw, tg)) in c.wall.iter().zip(&c.gas[1..]).enumerate() {
        println!("  {j:>8} {tw:>10.2} {tg:>10.2}");
    }
    println!(
        "  hot gas {:.2} K, cold gas {:.2} K",
        c.gas[0],
        c.gas[c.gas.len() - 1]
    );
    println!("  dynamic poles (1/s):");
    for pole in c
        .linear
        .dynamics
        .poles
        .iter()
        .filter(|p| p.im >= 0.0)
        .take(6)
    {
        println!(
            "    {:>12.4} {:+12.4}j ({:7.3} Hz){}",
            pole.re,
            pole.im,
            pole.freq_hz,
            if pole.rhp { "  unstable" } else { "" }
        );
    }
    let mg = &c.linear.margins;
    let fmt = |v: Option<f64>, unit: &str| {
        v.map(|v| format!("{v:.3} {unit}"))
            .unwrap_or_else(|| "none".into())
    };
    println!(
        "  loop at `{}`: Gm = {} at {}, Pm = {} at {}",
        c.linear.open_loop.full.name,
        fmt(mg.gain_db, "dB"),
        fmt(mg.phase_crossover_rad_s, "rad/s"),
        fmt(mg.phase_deg, "deg"),
        fmt(mg.gain_crossover_rad_s, "rad/s")
    );
}

/// The text report.
pub fn print(s: &Summary) {
    let m = &s.model;
    println!(
        "model {} (n = {}, closure {}, {} states)",
        m.name(),
        m.n(),
        m.closure(),
        m.n_states()
    );
    print_case(&s.chosen);
    print_case(&s.linear_profile);
    let growth = |c: &Case| {
        c.linear
            .dynamics
            .poles
            .first()
            .map(|p| p.re)
            .unwrap_or(f64::NAN)
    };
    println!(
        "growth rate of the leading pair: {:.4} 1/s (kappa = {}) vs {:.4} 1/s (linear profile)",
        growth(&s.chosen),
        s.chosen.kappa,
        growth(&s.linear_profile)
    );
}

/// The `--json` report.
pub fn json(s: &Summary) -> serde_json::Value {
    let case = |c: &Case| {
        serde_json::json!({
            "kappa": c.kappa,
            "wall_temperatures": c.wall,
            "gas_temperatures": c.gas,
            "linear": serde_json::to_value(c.linear.report(&s.model)).unwrap_or_default(),
        })
    };
    serde_json::json!({ "chosen": case(&s.chosen), "linear_profile": case(&s.linear_profile) })
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
            eprintln!("custom_profile: {e}");
            std::process::exit(1);
        }
    }
}
