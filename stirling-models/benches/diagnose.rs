//! The full-library diagnosis of a 3 s record at 2 kHz on `nsection` n = 2 with the seed's
//! sensors `p, x, y` (issue 15, item 6: at most 30 s wall on the 2-core machine), as one
//! process run after run: the record from the rig in process (no CSV), then
//! `diagnose::diagnose` with every candidate effect, its progress lines as it goes, and the
//! wall and CPU time of each run.
//!
//! `cargo bench -p stirling-models --bench diagnose -- [lag|coulomb|pair] [RUNS]`
//! - `lag` (default): `--effect sensor_lag=0.002`, seed 5, settle 0.1 s, diagnosed from
//!   `kd = 702.8, kp = 53.8, hh = 538` (the record of docs/diagnosis.md);
//! - `coulomb`: `--effect coulomb=0.02`, seed 11, settle 0.1 s, from the defaults;
//! - `pair` (issue 34, item 6: at most 30 s for two effects): `--effect regen_quadratic=1e8
//!   --effect sensor_lag=0.003`, seed 21, the rig's default settle, from the defaults (the
//!   record of `findings/several-effects.md`; both effects are named).
//!
//! A whole diagnosis takes tens of seconds, so this is a plain timing harness (the minimum
//! and median over `RUNS`, default 1), not criterion's sampling.

use std::time::Instant;

use stirling_models::diagnose::{self, DiagnoseOptions};
use stirling_models::rig::{self, RigConfig};

/// The CPU seconds (user + system) of this process so far, from `/proc/self/stat` (Linux,
/// 100 ticks a second); `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

/// The rig record and the starting parameter overrides of a case.
fn case(name: &str) -> (RigConfig, Vec<(&'static str, f64)>) {
    let (effects, seed, settle, set) = match name {
        "coulomb" => (vec!["coulomb=0.02"], 11, 0.1, vec![]),
        "pair" => (
            vec!["regen_quadratic=1e8", "sensor_lag=0.003"],
            21,
            RigConfig::default().settle,
            vec![],
        ),
        _ => (
            vec!["sensor_lag=0.002"],
            5,
            0.1,
            vec![("kd", 702.8), ("kp", 53.8), ("hh", 538.0)],
        ),
    };
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        effects: effects.into_iter().map(String::from).collect(),
        t_end: 3.0,
        settle,
        rate: 2000.0,
        seed,
        ..Default::default()
    };
    (cfg, set)
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let name = args.first().map_or("lag", |s| s.as_str()).to_string();
    let runs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1).max(1);
    let (cfg, set) = case(&name);
    let rec = rig::run(&cfg).expect("rig record");
    let (model, mut p0) = diagnose::nominal_model("nsection", Some(2)).expect("nominal model");
    for (k, v) in set {
        p0[model.param_index(k).expect("parameter")] = v;
    }
    let opts = DiagnoseOptions {
        progress: Some(|line: &str| eprintln!("  {line}")),
        ..Default::default()
    };
    let mut walls = Vec::new();
    for run in 1..=runs {
        let (clock, cpu0) = (Instant::now(), cpu_seconds());
        let d = diagnose::diagnose(model.as_ref(), &p0, &rec.data, &opts).expect("diagnosis");
        let wall = clock.elapsed().as_secs_f64();
        let cpu = cpu_seconds().zip(cpu0).map(|(b, a)| b - a);
        walls.push(wall);
        let verdict = serde_json::to_string(&d.verdict).unwrap_or_default();
        println!(
            "diagnose/{name} run {run}: {wall:.1} s wall, {} CPU",
            fmt_cpu(cpu)
        );
        println!("  verdict {verdict}");
        if let Some(top) = d.ranking.first() {
            let params: Vec<String> = top
                .params
                .iter()
                .map(|q| {
                    format!(
                        "{} {:.4e} [{:.4e}, {:.4e}]",
                        q.name, q.value, q.ci_low, q.ci_high
                    )
                })
                .collect();
            println!("  first: {} {}", top.effect, params.join(", "));
        }
    }
    walls.sort_by(f64::total_cmp);
    println!(
        "diagnose/{name}: {} runs, wall min {:.1} s, median {:.1} s",
        runs,
        walls[0],
        walls[walls.len() / 2]
    );
}

fn fmt_cpu(cpu: Option<f64>) -> String {
    cpu.map_or("-".into(), |c| format!("{c:.1} s"))
}
