//! Limit cycle with Floquet multipliers of `nsection` (full closure, default engine) by the
//! block route, the Newton-Krylov route and the dense-monodromy route: the timing tables of
//! docs/performance.md ("Limit cycles at large n", "Floquet at large n").
//!
//! `cargo run --release --example shooting_routes [-- --ns 100,400,1000 --dense-max 1000
//! --krylov-max 2100 --block-max 100000]`
//!
//! For every n: settle from the displacer at 5 mm (timed apart), then shoot from the settled
//! cycle by each route (the block one up to `--block-max` states, the Krylov one up to
//! `--krylov-max`, the dense one up to `--dense-max`), and print the wall times, the Newton
//! iterations, the counters, the leading multipliers, the peak memory so far, and the
//! differences of the cycles and multipliers from the dense route's. One timed run per route (a shot at n = 1000 takes minutes):
//! timings, not statistics; read them with the machine load (`uptime`) beside.

use std::time::Instant;

use stirling::dsl::Closure;
use stirling::models::sim::{
    self, shoot, shoot_block_counted, shoot_krylov_counted, BlockOptions, KrylovOptions,
    LimitCycle, ShootingOptions, SimOptions,
};

fn arg<T: std::str::FromStr>(args: &[String], name: &str) -> Option<T> {
    let i = args.iter().position(|a| a == name)?;
    args.get(i + 1)?.parse().ok()
}

fn show(route: &str, lc: &LimitCycle, secs: f64) {
    let fl: Vec<String> = lc
        .floquet
        .iter()
        .take(8)
        .map(|&(re, im)| format!("{re:.6}{im:+.6}i"))
        .collect();
    println!(
        "  {route:>6}: {secs:8.2} s, {} Newton iterations, residual {:.2e}, period {:.9} s, {} steps, {} Jacobians, {} LU",
        lc.iterations,
        lc.residual,
        lc.period,
        lc.stats.steps,
        lc.stats.jacobian_calls,
        lc.stats.lu_factorizations
    );
    println!("          multipliers: {}", fl.join(", "));
}

fn peak_rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let ns: Vec<usize> = match args.iter().position(|a| a == "--ns") {
        Some(i) => args[i + 1]
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()?,
        None => vec![100, 400, 1000],
    };
    let dense_max: usize = arg(&args, "--dense-max").unwrap_or(1000);
    let krylov_max: usize = arg(&args, "--krylov-max").unwrap_or(2100);
    let block_max: usize = arg(&args, "--block-max").unwrap_or(usize::MAX);
    let opts = ShootingOptions::default();
    for n in ns {
        let model = stirling::models::build("nsection", Some(n), Closure::Full)?;
        let (model, p) = (model.as_ref(), model.default_params());
        let mut x0 = vec![0.0; model.n_states()];
        model.equilibrium_guess(&p, &mut x0);
        x0[0] = 5e-3;
        let t = Instant::now();
        let st = sim::settle(
            model,
            &p,
            &x0,
            20.0,
            &[],
            3,
            1e-3,
            &SimOptions::default(),
            None,
        )?;
        println!(
            "n = {n} ({} states): settled at t = {:.3} s in {:.2} s",
            model.n_states(),
            st.t,
            t.elapsed().as_secs_f64()
        );
        let mut shots: Vec<(&str, LimitCycle)> = Vec::new();
        if model.n_states() <= block_max {
            let t = Instant::now();
            let (b, c) = shoot_block_counted(
                model,
                &p,
                &st.x0,
                st.period,
                &opts,
                &BlockOptions::default(),
            )?;
            show("block", &b, t.elapsed().as_secs_f64());
            println!(
                "          {} surrogate(s) ({} sweeps, {} Radau steps), {} difference run(s); multipliers: {} sweeps, {} columns, {} Radau steps",
                c.surrogates, c.surrogate_sweeps, c.surrogate_steps, c.differences, c.sweeps, c.columns, c.steps
            );
            println!("          peak RSS so far {:.0} MB", peak_rss_mb());
            shots.push(("block", b));
        }
        if model.n_states() <= krylov_max {
            let t = Instant::now();
            let kopts = KrylovOptions::default();
            let (k, c) = shoot_krylov_counted(model, &p, &st.x0, st.period, &opts, &kopts)?;
            show("krylov", &k, t.elapsed().as_secs_f64());
            println!(
                "          {} GMRES products, {} Arnoldi products; {} Radau steps, {} with stored factors",
                c.gmres_products, c.arnoldi_products, c.steps, c.cached_steps
            );
            println!("          peak RSS so far {:.0} MB", peak_rss_mb());
            shots.push(("krylov", k));
        }
        if model.n_states() <= dense_max {
            let t = Instant::now();
            let d = shoot(model, &p, &st.x0, st.period, &opts)?;
            show("dense", &d, t.elapsed().as_secs_f64());
            let s = sim::state_scale(model, &p);
            for (route, k) in &shots {
                let dx =
                    d.x0.iter()
                        .zip(&k.x0)
                        .zip(&s)
                        .map(|((a, b), w)| ((a - b) / w).abs())
                        .fold(0.0, f64::max);
                // every multiplier of the route above 1e-6 against the nearest dense one
                let worst = k
                    .floquet
                    .iter()
                    .filter(|m| m.0.hypot(m.1) >= 1e-6)
                    .map(|&(re, im)| {
                        d.floquet
                            .iter()
                            .map(|&(a, b)| (a - re).hypot(b - im))
                            .fold(f64::MAX, f64::min)
                    })
                    .fold(0.0, f64::max);
                println!(
                    "          {route} vs dense: period {:.2e}, scaled x0 {dx:.2e}, multipliers {worst:.2e}",
                    (d.period - k.period).abs() / d.period
                );
            }
        }
    }
    Ok(())
}
