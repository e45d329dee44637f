//! Free-run validation and multiple-shooting refinement on rig data from `cv1`.

use std::time::Instant;

use stirling::dsl::Closure;
use stirling::models::fit::{self, free_run, multiple_shooting, FitOptions};
use stirling::models::rig::{self, RigConfig};

const TRUTH: [&str; 6] = ["kd=680", "kp=58", "bd=0.55", "bp=8.4", "hh=560", "hk=450"];

fn rig_data() -> rig::RigOutput {
    let cfg = RigConfig {
        model: "cv1".into(),
        set: TRUTH.iter().map(|s| s.to_string()).collect(),
        t_end: 0.8,
        settle: 0.4,
        rate: 2000.0,
        noise_p: 50.0,
        noise_x: 20e-6,
        offset_p: 300.0,
        offset_x: 1.5e-3,
        offset_y: -2e-3,
        seed: 11,
        ..Default::default()
    };
    rig::run(&cfg).unwrap()
}

fn truth() -> Vec<(&'static str, f64)> {
    TRUTH
        .iter()
        .map(|s| {
            let (k, v) = s.split_once('=').unwrap();
            (k, v.parse().unwrap())
        })
        .collect()
}

#[test]
fn cv1_free_run_and_multiple_shooting() {
    let out = rig_data();
    let model = stirling::models::build("cv1", None, Closure::Full).unwrap();
    let p0 = model.default_params();
    let free: Vec<String> = truth().iter().map(|(k, _)| k.to_string()).collect();

    // two stages, then the free run on the held-out block from its measured initial state
    let opts = FitOptions {
        free: Some(free.clone()),
        ..Default::default()
    };
    let res = fit::identify(model.as_ref(), &p0, &out.data, &opts).unwrap();
    assert!(res.notes.is_empty(), "{:?}", res.notes);
    eprintln!("identify {:.2} s, offsets {:?}", res.seconds, res.offsets);
    let fr = res.free_run.as_ref().expect("free run");
    eprintln!(
        "free run on {:?} ({:.3} s short window, {:.3} s):",
        fr.block, fr.short_window, fr.seconds
    );
    for f in &fr.fits {
        eprintln!("  {} {:<15} {:.2} %", f.channel, f.block, f.fit_percent);
    }
    eprintln!("  measured  {:?}", fr.measured);
    eprintln!("  simulated {:?}", fr.simulated);
    eprintln!(
        "  frequency error {:?}, x phase lag at the end {:?} rad",
        fr.frequency_error, fr.x_phase_lag
    );
    for ch in ["x", "y", "p"] {
        let v = fr.fit_percent(ch, "free_run_short").unwrap();
        assert!(
            v > 90.0,
            "free-run fit of {ch} over the first cycles: {v:.2} %"
        );
    }
    let (m, s) = (
        fr.measured.as_ref().unwrap(),
        fr.simulated.as_ref().unwrap(),
    );
    assert!(
        fr.frequency_error.unwrap().abs() < 0.01,
        "{:?}",
        fr.frequency_error
    );
    assert!(fr.x_phase_lag.unwrap().abs() < 0.1);
    for ((ch, am), (_, as_)) in m.amplitude.iter().zip(&s.amplitude) {
        assert!(
            (as_ / am - 1.0).abs() < 0.05,
            "{ch} amplitude {as_} vs {am}"
        );
    }
    for ((ch, pm), (_, ps)) in m.phase.iter().zip(&s.phase) {
        assert!((ps - pm).abs() < 0.1, "{ch} phase {ps} vs {pm}");
    }

    // the same with the multiple-shooting refinement inside `identify`
    let opts_ms = FitOptions {
        multiple_shooting: Some(multiple_shooting::MsOptions::default()),
        ..opts
    };
    let res_ms = fit::identify(model.as_ref(), &p0, &out.data, &opts_ms).unwrap();
    assert!(res_ms.notes.is_empty(), "{:?}", res_ms.notes);
    eprintln!(
        "identify with refinement {:.2} s, offsets {:?}",
        res_ms.seconds, res_ms.offsets
    );
    let rm = res_ms.multiple_shooting.as_ref().expect("refinement");
    assert!(rm.converged);
    for (k, v) in truth() {
        let e = rm.estimate(k).unwrap();
        eprintln!(
            "  refined {k} {:.5e} [{:.5e}, {:.5e}]",
            e.value, e.ci_low, e.ci_high
        );
        assert!(
            e.covers(v),
            "{k}: truth {v} outside [{}, {}]",
            e.ci_low,
            e.ci_high
        );
    }
    for ch in ["x", "y", "p"] {
        let v = res_ms
            .free_run
            .as_ref()
            .unwrap()
            .fit_percent(ch, "free_run_short")
            .unwrap();
        assert!(v > 90.0, "refined free-run fit of {ch}: {v:.2} %");
    }

    // multiple shooting alone on 0.5 s of the training block, from the defaults (perturbed
    // from the truth) and the two stages' sensor offsets
    let clock = Instant::now();
    let idx: Vec<usize> = free.iter().map(|k| model.param_index(k).unwrap()).collect();
    let ms = multiple_shooting::multiple_shooting(
        model.as_ref(),
        &p0,
        &idx,
        &out.data,
        &res.offsets,
        res.train,
        &multiple_shooting::MsOptions::default(),
    )
    .unwrap();
    eprintln!(
        "multiple shooting: {} segments, {} it, converged {}, s2 = {:.3}, {:.2} s",
        ms.segments.len(),
        ms.iterations,
        ms.converged,
        ms.stats.sigma2,
        clock.elapsed().as_secs_f64()
    );
    for e in ms
        .stats
        .estimates
        .iter()
        .filter(|e| !e.name.starts_with("seg"))
    {
        eprintln!(
            "  {:<12} {:>13.6e} (from {:.4e}) +- {:.2e}  [{:.6e}, {:.6e}]",
            e.name, e.value, e.initial, e.std_error, e.ci_low, e.ci_high
        );
    }
    for f in &ms.fits {
        eprintln!("  fit {} {:.2} %", f.channel, f.fit_percent);
    }
    let worst = ms.segments.iter().map(|s| s.defect).fold(0.0, f64::max);
    eprintln!("  largest defect {worst:.2e}");
    for w in &ms.stats.warnings {
        eprintln!("  warning: {w}");
    }
    for (k, v) in truth() {
        let e = ms.estimate(k).unwrap();
        assert!(
            (e.initial / v - 1.0).abs() > 0.01,
            "{k} did not start perturbed"
        );
        assert!(
            e.covers(v),
            "{k}: truth {v} outside [{}, {}]",
            e.ci_low,
            e.ci_high
        );
    }
    for f in &ms.fits {
        // near the noise ceiling (p: 50 Pa noise on a ~870 Pa rms swing caps the fit at ~94 %)
        assert!(
            f.fit_percent > 90.0,
            "{} segment fit {:.2} %",
            f.channel,
            f.fit_percent
        );
    }

    // the free run with the refined parameters over two cycles from the measured state
    let mut p = p0.clone();
    for (k, (_, v)) in ms.params.iter().enumerate() {
        p[k] = *v;
    }
    let fr2 = free_run::free_run(
        model.as_ref(),
        &p,
        &out.data,
        &ms.offsets,
        res.holdout.unwrap(),
        &free_run::FreeRunOptions::default(),
    )
    .unwrap();
    for f in fr2.fits.iter().filter(|f| f.block == "free_run_short") {
        eprintln!("  refined free run {} {:.2} %", f.channel, f.fit_percent);
        assert!(f.fit_percent > 90.0, "{} {:.2} %", f.channel, f.fit_percent);
    }
}

/// The free run of `nsection` n = 2 (mass states, hot and cold pressures) at the truth from the
/// measured initial state.
#[test]
fn nsection_free_run_at_truth() {
    let cfg = RigConfig {
        model: "nsection".into(),
        channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        n: Some(2),
        t_end: 0.4,
        settle: 0.4,
        offset_p: 300.0,
        offset_x: 1.5e-3,
        offset_y: -2e-3,
        seed: 5,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let model = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let p = model.default_params();
    let off = free_run::SensorOffsets {
        x: 1.5e-3,
        y: -2e-3,
        p: 300.0,
        p_hot: Some(300.0),
        ..Default::default()
    };
    let fr = free_run::free_run(
        model.as_ref(),
        &p,
        &out.data,
        &off,
        (0.0, 0.4),
        &free_run::FreeRunOptions::default(),
    )
    .unwrap();
    for f in &fr.fits {
        eprintln!("  {} {:<15} {:.2} %", f.channel, f.block, f.fit_percent);
    }
    eprintln!(
        "  frequency error {:?}, x phase lag {:?}",
        fr.frequency_error, fr.x_phase_lag
    );
    assert_eq!(fr.fits.len(), 8, "x, y, p, p_hot on two windows");
    for f in fr.fits.iter().filter(|f| f.block == "free_run_short") {
        assert!(f.fit_percent > 90.0, "{} {:.2} %", f.channel, f.fit_percent);
    }
}
