//! `stirling simulate` on a kinematic engine pushed with `--start omega=...`: the run reports
//! the engine's speed and indicated power over its last whole revolutions and Schmidt's
//! isothermal analysis at the gas's cycle-mean temperatures (`sim::running`, `sim::schmidt`);
//! a run that does not turn says how to push it; a state the model lacks is refused by name.

mod support;

use std::path::PathBuf;

use support::{fails_with, prints as ok};

fn engine(name: &str) -> String {
    let p: PathBuf = [
        env!("CARGO_MANIFEST_DIR"),
        "..",
        "examples",
        "engines",
        name,
    ]
    .iter()
    .collect();
    p.display().to_string()
}

#[test]
fn a_pushed_gamma_engine_reports_its_speed_power_and_schmidt() {
    let gamma = engine("gamma_ltd.stirling");
    let args = [
        "simulate",
        gamma.as_str(),
        "--t-end",
        "12",
        "--start",
        "omega=6.3",
        "--samples",
        "20000",
    ];
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let s: serde_json::Value = serde_json::from_str(&ok(&json_args)).unwrap();
    let r = &s["running"];
    let hz = r["hz"].as_f64().unwrap();
    let work = r["work"].as_f64().unwrap();
    // kit engines of this kind turn at about 150 rpm; docs/physics.md: 2.81 Hz, 2.24 mW
    assert!((2.3..3.2).contains(&hz), "{s}");
    assert!(
        work > 0.0 && (1.5e-3..3.5e-3).contains(&r["power"].as_f64().unwrap()),
        "{s}"
    );
    let sch = &s["schmidt"];
    let ideal = sch["work"].as_f64().unwrap();
    // the isothermal engine at the same temperatures does more work than the real one
    assert!(ideal > work, "{s}");
    // Schmidt's spaces: the gas's entropy returns, sum W_i / T_i = 0
    let spaces = sch["spaces"].as_array().unwrap();
    assert_eq!(spaces.len(), 2, "{s}");
    let (entropy, scale) = spaces.iter().fold((0.0, 0.0), |(e, m), sp| {
        let (w, t) = (
            sp["work"].as_f64().unwrap(),
            sp["temperature"].as_f64().unwrap(),
        );
        (e + w / t, f64::max(m, (w / t).abs()))
    });
    assert!(entropy.abs() < 1e-6 * scale, "{entropy} of {scale}: {s}");
    // the hot space's mean gas temperature lies between the plates'
    let hot = spaces[0]["temperature"].as_f64().unwrap();
    assert!((295.15..353.15).contains(&hot), "{s}");
    let text = ok(&args);
    assert!(
        text.contains("running: ") && text.contains(" rpm)"),
        "{text}"
    );
    assert!(text.contains("Schmidt (isothermal spaces"), "{text}");
    assert!(text.contains("of Schmidt's work"), "{text}");
}

#[test]
fn an_engine_that_does_not_turn_is_told_how_to_push_it() {
    let beta = engine("beta.stirling");
    let out = ok(&["simulate", &beta, "--t-end", "2"]);
    assert!(
        out.contains("not running:") && out.contains("--start omega="),
        "{out}"
    );
    fails_with(
        &["simulate", &beta, "--t-end", "1", "--start", "spin=3"],
        &["has no state `spin`", "theta", "omega"],
    );
}
