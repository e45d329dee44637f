//! Stage 1 restarted from the measured body states (`FitOptions::restart_cycles`, `stirling fit
//! --restart-cycles`): a piston between end stops is an impact oscillator, and one driven run
//! over the whole block settles on another response than the engine's even at the rig's own
//! parameters; restarted every half cycle it follows the record.

use stirling::models::diagnose::nominal_model;
use stirling::models::fit::{self, FitOptions};
use stirling::models::rig::{self, RigConfig};

/// Stage 1's fit percentage of the piston on the training block.
fn piston_fit(restart_cycles: Option<f64>) -> f64 {
    let cfg = RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 2.0,
        seed: 31,
        effects: ["kc=2e5", "xmax=0.002", "ymax=0.0011"]
            .map(String::from)
            .to_vec(),
        ..Default::default()
    };
    let out = rig::run(&cfg).unwrap();
    // the model that made the record: the augmented member with the stops at the truth
    let (model, mut p0) = nominal_model("nsection", Some(2)).unwrap();
    for (k, v) in [("kc", 2e5), ("xmax", 0.002), ("ymax", 0.0011)] {
        p0[model.param_index(k).unwrap()] = v;
    }
    let opts = FitOptions {
        free: Some(vec!["bd".into()]),
        free_run: None,
        input_noise_draws: 0,
        restart_cycles,
        ..Default::default()
    };
    let id = fit::identify(model.as_ref(), &p0, &out.data, &opts).unwrap();
    id.stage1.unwrap().fit_percent("y", "train").unwrap()
}

#[test]
fn restarts_let_stage_one_follow_a_piston_between_end_stops() {
    let once = piston_fit(None);
    let restarted = piston_fit(Some(0.5));
    eprintln!("piston fit: one run {once:.1} %, restarted {restarted:.1} %");
    // measured on seed 31 (3 s): -61 % in one run, 83 % restarted every half cycle
    assert!(once < 50.0, "one run fits the piston {once:.1} %");
    assert!(restarted > 75.0, "restarted: {restarted:.1} %");
}
