//! The dominant pole pair of `nsection` (full closure, default engine) against the number of
//! regenerator sections n = 1 .. 10,000: the convergence table of docs/performance.md.
//!
//! `cargo run --release --example pole_convergence [-- --ns 1,2,5,...]`
//!
//! Every n takes the route `linearize` takes (dense up to 400 states, sparse dominant above);
//! the table gives the rightmost pair (re in 1/s, im in rad/s and Hz), its change from the
//! previous row, the route and the wall time.

use std::time::Instant;

use stirling::dsl::Closure;
use stirling::models::linear::{dynamic_poles, NewtonOptions, PoleRoute};

const NS: [usize; 13] = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 10_000];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let ns: Vec<usize> = match args.iter().position(|a| a == "--ns") {
        Some(i) => args[i + 1]
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()?,
        None => NS.to_vec(),
    };
    println!("| n | states | route | re (1/s) | im (rad/s) | f (Hz) | change of s from previous n | time |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut prev: Option<(f64, f64)> = None;
    for n in ns {
        let model = stirling::models::build("nsection", Some(n), Closure::Full)?;
        let p = model.default_params();
        let t = Instant::now();
        let d = dynamic_poles(model.as_ref(), &p, &NewtonOptions::default())?;
        let dt = t.elapsed().as_secs_f64();
        let top = d
            .poles
            .iter()
            .find(|q| q.im > 0.0)
            .ok_or_else(|| format!("n = {n}: no complex pole"))?;
        let change = prev.map_or("-".to_string(), |(re, im)| {
            format!(
                "{:.2e}",
                (top.re - re).hypot(top.im - im) / top.re.hypot(top.im)
            )
        });
        let route = match d.route {
            PoleRoute::Dense => "dense",
            PoleRoute::SparseDominant { .. } => "sparse",
        };
        println!(
            "| {n} | {} | {route} | {:.6} | {:.6} | {:.6} | {change} | {:.3} s |",
            model.n_states(),
            top.re,
            top.im,
            top.freq_hz,
            dt
        );
        prev = Some((top.re, top.im));
    }
    Ok(())
}
