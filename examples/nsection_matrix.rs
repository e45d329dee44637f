//! `nsection` with a regenerator matrix of finite heat capacity, declared by extending the
//! family's `nsection_engine` (no copy of the default engine), at run-time `n`.
//!
//! ```text
//! cargo run --release --example nsection_matrix -- [N] [--t-max SECONDS] [--json]
//! ```
//!
//! Prints the dominant pole pair, the limit cycle (frequency, strokes) and the indicated power
//! of the seed's 8th-order model (`nsection` with two sections, alias `order8`), of the
//! fixed-wall `nsection` at `N` (default 10; the matrix of infinite capacity) and of the
//! matrix at 5 kJ/K down to 0.05 J/K (a steel-mesh matrix of the default engine's regenerator,
//! about 0.1 kg of steel, is about 50 J/K). The model and the study are in
//! `examples/support/matrix_study.rs`.

#[path = "support/matrix_study.rs"]
mod matrix_study;

use matrix_study::{study, Case};

/// Matrix capacities studied (J/K).
const CAPACITIES: [f64; 6] = [5000.0, 500.0, 50.0, 5.0, 0.5, 0.05];

/// Command-line options.
struct Args {
    n: usize,
    t_max: f64,
    json: bool,
}

#[derive(Debug, thiserror::Error)]
enum ArgError {
    #[error("expected a number of sections >= 1, found `{0}`\nusage: nsection_matrix [N] [--t-max SECONDS] [--json]")]
    Sections(String),
    #[error("--t-max needs a positive number of seconds")]
    TMax,
}

fn parse_args() -> Result<Args, ArgError> {
    let mut args = Args {
        n: 10,
        t_max: 8.0,
        json: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--json" => args.json = true,
            "--t-max" => {
                args.t_max = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .filter(|v: &f64| v.is_finite() && *v > 0.0)
                    .ok_or(ArgError::TMax)?
            }
            s => {
                args.n = s
                    .parse()
                    .ok()
                    .filter(|&n| n >= 1)
                    .ok_or(ArgError::Sections(s.into()))?
            }
        }
    }
    Ok(args)
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let args = parse_args()?;
    let cases = study(args.n, &CAPACITIES, args.t_max)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&cases)?);
        return Ok(());
    }
    print_table(args.n, &cases);
    Ok(())
}

fn print_table(n: usize, cases: &[Case]) {
    println!("nsection n = {n} with a regenerator matrix of heat capacity C (axial conductance 0.03 W/K)");
    println!("baseline: the seed's 8th-order model (nsection n = 2, fixed wall)\n");
    println!(
        "{:<44} {:>6} {:>11} {:>11} {:>8} {:>9} {:>9} {:>9} {:>8}",
        "model", "states", "re [1/s]", "im [rad/s]", "f [Hz]", "x [mm]", "y [mm]", "P [W]", "P/P8"
    );
    let base = cases[0].power_w;
    for c in cases {
        println!(
            "{:<44} {:>6} {:>11.4} {:>11.3} {:>8.3} {:>9.3} {:>9.3} {:>9.4} {:>8.4}",
            c.label,
            c.n_states,
            c.pole.0,
            c.pole.1,
            c.frequency_hz,
            1e3 * c.x_stroke,
            1e3 * c.y_stroke,
            c.power_w,
            c.power_w / base
        );
    }
    println!("\nx, y: strokes peak to peak; P: indicated power; P/P8: against the 8th-order model");
}
