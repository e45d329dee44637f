//! The virtual rig: CSV + truth sidecar, seeded noise, refuses to overwrite.

use stirling::models::data::read_csv;
use stirling::models::rig::{self, RigConfig};

#[test]
fn rig_writes_csv_and_truth_and_is_reproducible() {
    let dir = std::env::temp_dir().join(format!("stirling_rig_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("cv1.csv");
    let cfg = RigConfig {
        model: "cv1".into(),
        t_end: 0.2,
        effects: vec!["leak=2e-8".into(), "sensor_gain=0.02".into()],
        offset_x: 1e-3,
        seed: 7,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    let side = rig::write(&out, &f, false).unwrap();
    let back = read_csv(&f).unwrap();
    assert_eq!(back.len(), 401);
    assert_eq!(back.channels(), vec!["p", "x", "y"]);
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&side).unwrap()).unwrap();
    assert_eq!(truth["model"], "cv1_fx");
    assert_eq!(truth["seed"], 7);
    assert_eq!(truth["parameters"]["Gleak"], 2e-8);
    assert_eq!(
        truth["active_effects"],
        serde_json::json!(["leak", "sensor_gain"])
    );
    let e = rig::write(&out, &f, false).unwrap_err().to_string();
    assert!(e.contains("pass --force"), "{e}");
    rig::write(&out, &f, true).unwrap();
    let again = rig::run(&cfg).unwrap();
    assert_eq!(again.data, out.data, "same seed, same record");
    // noise level: a clean run differs by noise of the requested size
    let clean = rig::run(&RigConfig {
        noise_p: 0.0,
        noise_x: 0.0,
        ..cfg.clone()
    })
    .unwrap();
    let d: Vec<f64> = out
        .data
        .p
        .as_ref()
        .unwrap()
        .iter()
        .zip(clean.data.p.as_ref().unwrap())
        .map(|(a, b)| a - b)
        .collect();
    let sd = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
    assert!((sd - 50.0).abs() < 7.0, "p noise sd {sd}");
    let mx = out.data.x.as_ref().unwrap().iter().sum::<f64>() / 401.0;
    assert!((mx - 1e-3).abs() < 1e-3, "offset present: {mx}");
}

#[test]
fn nsection_rig_has_hot_pressure() {
    let cfg = RigConfig {
        model: "nsection".into(),
        channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        n: Some(2),
        t_end: 0.05,
        effects: vec!["regen_quadratic=1e9".into()],
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    assert_eq!(out.data.channels(), vec!["p", "p_hot", "x", "y"]);
    assert_eq!(out.truth.model, "nsection_fx");
}

#[test]
fn rig_writes_the_seeds_sensor_set_by_default() {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 0.02,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    assert_eq!(out.data.channels(), vec!["p", "x", "y"]);
    assert!(!out.truth.offsets.contains_key("p_hot"));
}

#[test]
fn rig_refuses_nonphysical_truths() {
    let base = RigConfig {
        model: "cv1".into(),
        t_end: 0.02,
        ..Default::default()
    };
    let cases: Vec<(RigConfig, &str)> = vec![
        (
            RigConfig {
                effects: vec!["coulomb=-0.3".into()],
                ..base.clone()
            },
            "`Fcd` = -0.3 is not physical",
        ),
        (
            RigConfig {
                effects: vec!["leak=-1e-8".into()],
                ..base.clone()
            },
            "`Gleak` = -0.00000001 is not physical",
        ),
        (
            RigConfig {
                effects: vec!["xmax=-0.01".into()],
                ..base.clone()
            },
            "must be > 0",
        ),
        (
            RigConfig {
                effects: vec!["gain_x=-2".into()],
                ..base.clone()
            },
            "between -0.5 and 0.5",
        ),
        (
            RigConfig {
                effects: vec!["sensor_lag=-0.001".into()],
                ..base.clone()
            },
            "`tau_p`",
        ),
        (
            RigConfig {
                rate: 1.0,
                ..base.clone()
            },
            "--rate must be between",
        ),
        (
            RigConfig {
                noise_p: 1e5,
                ..base.clone()
            },
            "pressure would go negative",
        ),
        (
            RigConfig {
                channels: vec!["p_hot".into()],
                ..base.clone()
            },
            "single gas volume",
        ),
        (
            RigConfig {
                channels: vec!["q".into()],
                ..base.clone()
            },
            "unknown channel `q`",
        ),
    ];
    for (cfg, want) in cases {
        let e = rig::run(&cfg).unwrap_err().to_string();
        assert!(e.contains(want), "expected `{want}` in: {e}");
    }
}
