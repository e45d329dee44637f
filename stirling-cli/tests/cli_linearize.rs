//! `stirling linearize` and `stirling locus` on the built binary: the JSON report of `schmidt`,
//! the plots, and clear errors for malformed requests.

use std::process::{Command, Output};

fn stirling(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn fails_with(args: &[&str], needle: &str) {
    let out = stirling(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(
        err.contains(needle),
        "{args:?}: stderr `{err}` lacks `{needle}`"
    );
}

#[test]
fn schmidt_json_carries_the_reference_numbers() {
    let out = stirling(&["linearize", "schmidt", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["model"], "schmidt");
    assert_eq!(r["n"], 1);
    assert_eq!(r["closure"], "full");
    assert_eq!(r["n_states"], 4);
    assert_eq!(r["state_names"].as_array().unwrap().len(), 4);
    assert!(r["equilibrium"]["x"].is_array());
    let p0 = &r["poles"][0];
    assert!(
        (p0["re"].as_f64().unwrap() - 9.6225).abs() < 1e-3
            && (p0["im"].as_f64().unwrap() - 89.5373).abs() < 1e-3
    );
    assert_eq!(p0["rhp"], true);
    assert!(r["inventory_mode"].is_null());
    assert_eq!(r["loop"]["channel"], "pressure");
    let m = &r["margins"];
    let f = |k: &str| m[k].as_f64().unwrap();
    assert!(
        (f("gain_db") + 6.630).abs() < 0.01 && (f("phase_crossover_rad_s") - 81.60).abs() < 0.01
    );
    assert!(
        (f("phase_deg") + 79.50).abs() < 0.05 && (f("gain_crossover_rad_s") - 91.30).abs() < 0.01
    );
}

#[test]
fn full_models_report_the_inventory_mode_and_a_body_channel() {
    let out = stirling(&[
        "linearize",
        "nsection",
        "--n",
        "2",
        "--channel",
        "displacer",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["n_states"], 12);
    assert_eq!(r["poles"].as_array().unwrap().len(), 11);
    assert!(r["inventory_mode"]["eigenvalue"].as_f64().unwrap().abs() < 1e-6);
    assert_eq!(r["loop"]["channel"], "displacer");
    assert_eq!(r["loop"]["unit"], "N");
}

#[test]
fn plots_are_written() {
    let dir = std::env::temp_dir().join(format!("stirling-cli-linearize-{}", std::process::id()));
    let d = dir.to_str().unwrap();
    assert!(stirling(&["linearize", "cv1", "--plot", d])
        .status
        .success());
    assert!(stirling(&[
        "locus", "schmidt", "--param", "Th", "--from", "500", "--to", "700", "--steps", "3",
        "--plot", d
    ])
    .status
    .success());
    for f in ["poles.svg", "bode.svg", "locus.svg"] {
        let text = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(text.starts_with("<svg") && text.len() > 1000, "{f}");
    }
    let bode = std::fs::read_to_string(dir.join("bode.svg")).unwrap();
    assert!(bode.contains("Gm = ") && bode.contains("Pm = "));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn locus_json_over_th() {
    let out = stirling(&[
        "locus", "cv1", "--param", "Th", "--from", "400", "--to", "800", "--steps", "3", "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let l: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pts = l["points"].as_array().unwrap();
    assert_eq!(pts.len(), 3);
    assert_eq!(pts[1]["value"], 600.0);
    // Growth of the engine mode rises with the hot temperature.
    let re = |i: usize| pts[i]["poles"][0]["re"].as_f64().unwrap();
    assert!(re(0) < re(1) && re(1) < re(2));
}

#[test]
fn malformed_requests_fail_clearly() {
    fails_with(&["linearize", "stirling9"], "unknown model `stirling9`");
    fails_with(
        &["linearize", "nsection", "--n", "0"],
        "invalid value '0' for '--n <N>': must be at least 1",
    );
    fails_with(
        &["linearize", "schmidt", "--set", "Tx=3"],
        "unknown parameter `Tx`",
    );
    fails_with(
        &["linearize", "cv2", "--channel", "pressure"],
        "loop channel `pressure` does not exist for model `cv2`; valid channels: displacer, piston",
    );
    fails_with(
        &["linearize", "schmidt", "--channel", "crank"],
        "valid channels: pressure, displacer, piston",
    );
    fails_with(
        &[
            "locus", "schmidt", "--param", "Tx", "--from", "1", "--to", "2",
        ],
        "unknown parameter `Tx`",
    );
    fails_with(
        &[
            "locus", "schmidt", "--param", "Th", "--from", "200", "--to", "400", "--steps", "3",
        ],
        "hotter than the cold wall",
    );
    fails_with(
        &[
            "locus", "schmidt", "--param", "Th", "--from", "500", "--to", "600", "--steps", "0",
        ],
        "invalid value '0' for '--steps <STEPS>': must be at least 1",
    );
}
