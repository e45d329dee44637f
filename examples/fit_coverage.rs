//! Interval coverage of the two-stage fit on seeded rig records of the seed's sensor set
//! (`t, p, x, y`; the hot-side pressure unmeasured).
//!
//! For each seed: a start-up record of `nsection` (growing from 0.5 mm, absolute position
//! readings as on the seed's rig), the fit started from parameters perturbed at random by up
//! to `--perturb`, and for every free parameter whether its 95 % interval covers the truth.
//! Prints per parameter the coverage and the median interval width relative to the value,
//! and the free run's amplitude and frequency errors on the held-out block.
//!
//!     cargo run --release --example fit_coverage -- [--seeds 20] [--first 1] [--n 2] [--t-end 3]
//!                                                   [--perturb 0.08] [--threads 2]

use std::sync::Mutex;

use rand::{rngs::StdRng, Rng, SeedableRng};
use stirling::dsl::Closure;
use stirling::models::fit::{self, FitOptions};
use stirling::models::rig::{self, RigConfig};

const FREE: [&str; 7] = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"];

struct Args {
    first: u64,
    seeds: u64,
    n: usize,
    t_end: f64,
    perturb: f64,
    threads: usize,
}

fn args() -> Result<Args, String> {
    let mut a = Args {
        first: 1,
        seeds: 20,
        n: 2,
        t_end: 3.0,
        perturb: 0.08,
        threads: 2,
    };
    let v: Vec<String> = std::env::args().skip(1).collect();
    for w in v.chunks(2) {
        let val = w.get(1).ok_or(format!("{} needs a value", w[0]))?;
        let bad = |_| format!("bad value `{val}` for {}", w[0]);
        match w[0].as_str() {
            "--seeds" => a.seeds = val.parse().map_err(bad)?,
            "--first" => a.first = val.parse().map_err(bad)?,
            "--n" => a.n = val.parse().map_err(bad)?,
            "--t-end" => a.t_end = val.parse().map_err(|_| format!("bad --t-end {val}"))?,
            "--perturb" => a.perturb = val.parse().map_err(|_| format!("bad --perturb {val}"))?,
            "--threads" => a.threads = val.parse().map_err(bad)?,
            o => return Err(format!("unknown option {o}")),
        }
    }
    Ok(a)
}

/// One record's outcome: per parameter (covers, relative width, relative error), and the
/// free run's amplitude error of x, y, p and frequency error (relative).
type Outcome = (Vec<(bool, f64, f64)>, Option<[f64; 4]>);

fn one(seed: u64, a: &Args) -> Result<Outcome, String> {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(a.n),
        t_end: a.t_end,
        x0: 5e-4,
        offset_x: 0.131,
        offset_y: 0.046,
        offset_p: 50.0,
        seed,
        ..Default::default()
    };
    let out = rig::run(&cfg).map_err(|e| e.to_string())?;
    let model =
        stirling::models::build("nsection", Some(a.n), Closure::Full).map_err(|e| e.to_string())?;
    let mut p0 = model.default_params();
    let mut rng = StdRng::seed_from_u64(1000 + seed);
    for name in FREE {
        let j = model.param_index(name).expect("family parameter");
        p0[j] *= 1.0 + a.perturb * (2.0 * rng.gen::<f64>() - 1.0);
    }
    let opts = FitOptions {
        free: Some(FREE.map(String::from).to_vec()),
        ..Default::default()
    };
    let id = fit::identify(model.as_ref(), &p0, &out.data, &opts).map_err(|e| e.to_string())?;
    for st in [&id.stage1, &id.stage2].into_iter().flatten() {
        if !st.converged {
            eprintln!(
                "seed {seed}: {} did not converge in {} iterations",
                st.stage, st.iterations
            );
        }
    }
    let mut per = Vec::new();
    for name in FREE {
        let truth = out.truth.parameters[name];
        let e = id.estimate(name).ok_or(format!("{name} not estimated"))?;
        if !e.covers(truth) {
            eprintln!(
                "seed {seed}: {name} {:.5e} [{:.5e}, {:.5e}], truth {truth:.5e}, start {:.5e}",
                e.value, e.ci_low, e.ci_high, e.initial
            );
        }
        per.push((
            e.covers(truth),
            (e.ci_high - e.ci_low) / truth.abs(),
            (e.value - truth) / truth.abs(),
        ));
    }
    let fr = id.free_run.as_ref().and_then(|f| {
        let (m, s) = (f.measured.as_ref()?, f.simulated.as_ref()?);
        let amp = |c: &stirling::models::fit::free_run::CycleFeatures, ch: &str| {
            c.amplitude.iter().find(|a| a.0 == ch).map(|a| a.1)
        };
        let rel = |ch: &str| Some((amp(s, ch)? - amp(m, ch)?) / amp(m, ch)?);
        Some([rel("x")?, rel("y")?, rel("p")?, f.frequency_error?])
    });
    Ok((per, fr))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn main() {
    let a = match args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("fit_coverage: {e}");
            std::process::exit(2);
        }
    };
    let results: Mutex<Vec<(u64, Result<Outcome, String>)>> = Mutex::new(Vec::new());
    let next = Mutex::new(a.first);
    std::thread::scope(|s| {
        for _ in 0..a.threads.max(1) {
            s.spawn(|| loop {
                let seed = {
                    let mut g = next.lock().expect("lock");
                    let k = *g;
                    *g += 1;
                    k
                };
                if seed >= a.first + a.seeds {
                    break;
                }
                let r = one(seed, &a);
                match &r {
                    Ok((per, _)) => eprintln!(
                        "seed {seed}: covered {}/{}",
                        per.iter().filter(|c| c.0).count(),
                        per.len()
                    ),
                    Err(e) => eprintln!("seed {seed}: failed: {e}"),
                }
                results.lock().expect("lock").push((seed, r));
            });
        }
    });
    let res = results.into_inner().expect("lock");
    let ok: Vec<&Outcome> = res.iter().filter_map(|(_, r)| r.as_ref().ok()).collect();
    println!(
        "nsection n = {}, {} s start-up records, p,x,y: {} of {} fits ran",
        a.n,
        a.t_end,
        ok.len(),
        res.len()
    );
    println!("| parameter | coverage of 95 % intervals | median width / value | median |error| / value |");
    println!("|---|---|---|---|");
    for (k, name) in FREE.iter().enumerate() {
        let cov = ok.iter().filter(|o| o.0[k].0).count();
        let w = median(ok.iter().map(|o| o.0[k].1).collect());
        let e = median(ok.iter().map(|o| o.0[k].2.abs()).collect());
        println!(
            "| {name} | {cov}/{} ({:.0} %) | {:.2} % | {:.2} % |",
            ok.len(),
            100.0 * cov as f64 / ok.len().max(1) as f64,
            100.0 * w,
            100.0 * e
        );
    }
    let fr: Vec<[f64; 4]> = ok.iter().filter_map(|o| o.1).collect();
    for (k, what) in ["x amplitude", "y amplitude", "p amplitude", "frequency"]
        .iter()
        .enumerate()
    {
        let v: Vec<f64> = fr.iter().map(|f| f[k].abs()).collect();
        let worst = v.iter().copied().fold(0.0, f64::max);
        println!(
            "free run {what}: median |error| {:.2} %, worst {:.2} % ({} records)",
            100.0 * median(v.clone()),
            100.0 * worst,
            v.len()
        );
    }
}
