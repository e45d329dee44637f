//! Diagnostics of the two-stage fit (ignored; run with --ignored --nocapture).

use stirling::dsl::Closure;
use stirling::models::fit::{self, FitOptions};
use stirling::models::rig::{self, RigConfig};

fn show(res: &fit::Identification) {
    eprintln!("total {:.2} s", res.seconds);
    for st in [res.stage1.as_ref(), res.stage2.as_ref()]
        .into_iter()
        .flatten()
    {
        eprintln!(
            "{}: {} it, converged {}, s2 = {:.3}",
            st.stage, st.iterations, st.converged, st.stats.sigma2
        );
        for e in &st.stats.estimates {
            eprintln!(
                "  {:<12} {:>13.6e} +- {:.2e}  [{:.6e}, {:.6e}]",
                e.name, e.value, e.std_error, e.ci_low, e.ci_high
            );
        }
        for f in &st.fits {
            eprintln!(
                "  fit {} {} {:.3} % rms {:.3e}",
                f.channel, f.block, f.fit_percent, f.rms
            );
        }
        for w in &st.stats.warnings {
            eprintln!("  warning: {w}");
        }
    }
}

fn case(model: &str, n: Option<usize>, noise: bool, offsets: bool, stage2: bool) {
    let truth = [
        "kd=680", "kp=58", "bd=0.55", "bp=8.4", "hh=560", "hk=450", "Rf=1.3e5",
    ];
    let set: Vec<String> = truth
        .iter()
        .filter(|s| model != "cv1" || !s.starts_with("Rf"))
        .map(|s| s.to_string())
        .collect();
    let cfg = RigConfig {
        model: model.into(),
        n,
        set: set.clone(),
        t_end: 0.8,
        settle: 0.4,
        rate: 2000.0,
        noise_p: if noise {
            std::env::var("NP")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(50.0)
        } else {
            0.0
        },
        noise_x: if noise {
            std::env::var("NX")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(20e-6)
        } else {
            0.0
        },
        offset_p: if offsets {
            std::env::var("OP")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(300.0)
        } else {
            0.0
        },
        offset_x: if offsets { 1.5e-3 } else { 0.0 },
        offset_y: if offsets { -2e-3 } else { 0.0 },
        seed: std::env::var("SEED")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(11),
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let m = stirling::models::build(model, n, Closure::Full).unwrap();
    let p0 = m.default_params();
    let free: Vec<String> = set
        .iter()
        .map(|s| s.split_once('=').unwrap().0.to_string())
        .collect();
    let mut opts = FitOptions {
        free: Some(free),
        stage2,
        ..Default::default()
    };
    if let Some(c) = std::env::var("BURN").ok().and_then(|v| v.parse().ok()) {
        opts.burn_in = c;
    }
    if let Some(c) = std::env::var("CUT").ok().and_then(|v| v.parse().ok()) {
        opts.drift_cut = c;
    }
    let res = fit::identify(m.as_ref(), &p0, &out.data, &opts).unwrap();
    eprintln!("=== {model} {n:?} noise {noise} offsets {offsets}");
    show(&res);
}

#[test]
#[ignore]
fn diag_cv1_clean() {
    case("cv1", None, false, false, false);
}

#[test]
#[ignore]
fn diag_cv1_noisy() {
    case("cv1", None, true, true, std::env::var("S2").is_ok());
}

#[test]
#[ignore]
fn diag_ns_clean() {
    let noisy = std::env::var("NOISY").is_ok();
    case("nsection", Some(2), noisy, noisy, true);
}

/// Time of a full two-stage fit of nsection n = 2 on 3 s of data at 2 kHz
/// (`cargo test --release --test fit_diag -- --ignored --nocapture timing`).
#[test]
#[ignore]
fn timing_nsection2_3s() {
    let cfg = RigConfig {
        model: "nsection".into(),
        channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        n: Some(2),
        set: [
            "kd=680", "kp=58", "bd=0.55", "bp=8.4", "hh=560", "hk=450", "Rf=1.3e5",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect(),
        t_end: 3.0,
        settle: 0.4,
        rate: 2000.0,
        offset_p: 300.0,
        seed: 11,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let m = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let p0 = m.default_params();
    let clock = std::time::Instant::now();
    let res = fit::identify(
        m.as_ref(),
        &p0,
        &out.data,
        &FitOptions {
            free: Some(
                ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"]
                    .iter()
                    .map(|s| s.to_string())
                    .collect(),
            ),
            ..Default::default()
        },
    )
    .unwrap();
    eprintln!(
        "two-stage fit of nsection n = 2, 3 s at 2 kHz: {:.2} s",
        clock.elapsed().as_secs_f64()
    );
    show(&res);
}
