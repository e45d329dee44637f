//! Identification on the seed's sensor set: a start-up record of `nsection` n = 2 with the
//! cold-side pressure `p` and the positions `x`, `y` only (absolute position readings, as on
//! the seed's rig). The hot-side pressure the displacer feels is estimated by the gas stage;
//! the intervals must cover the truth and the calibrated model's free run must match the
//! record. The coverage over 20 seeded records is measured by `examples/fit_coverage.rs`.

mod common;

use stirling::dsl::Closure;
use stirling::models::fit::{self, FitOptions};
use stirling::models::rig::{self, RigConfig};

#[test]
fn pxy_startup_record_recovers_parameters_and_free_run() {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 3.0,
        x0: 5e-4,
        offset_x: 0.131,
        offset_y: 0.046,
        offset_p: 50.0,
        seed: 2,
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    assert_eq!(out.data.channels(), vec!["p", "x", "y"]);
    let model = stirling::models::build("nsection", Some(2), Closure::Full).unwrap();
    let mut p0 = model.default_params();
    for (k, v) in [
        ("kd", 683.0),
        ("hh", 650.0),
        ("hk", 650.0),
        ("bp", 7.1),
        ("Rf", 1.5e5),
    ] {
        p0[model.param_index(k).unwrap()] = v;
    }
    let free = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"];
    let opts = FitOptions {
        free: Some(free.map(String::from).to_vec()),
        ..Default::default()
    };
    let id = fit::identify(model.as_ref(), &p0, &out.data, &opts).unwrap();
    common::fit::assert_recovered(&id, free.map(|k| (k, out.truth.parameters[k])), 0.3);
    common::fit::assert_free_run_amplitudes(&id, &["x", "y", "p"], 0.05);
    let fr = id
        .free_run
        .as_ref()
        .expect("free run on the held-out block");
    let fe = fr.frequency_error.unwrap();
    assert!(
        fe.abs() < 0.005,
        "free-run frequency off by {:.3} %",
        100.0 * fe
    );
}
