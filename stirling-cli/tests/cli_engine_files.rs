//! An engine the family does not have, declared in a `.stirling` file that the test writes,
//! run from the command line alone: `stirling info`, `linearize`, `simulate`, `rig`, `fit`
//! and `diagnose` take the file's path where they take a family name, at the `--n` asked
//! for. The poles are the same model's through the Rust API; the fit recovers the truth
//! within its intervals; the diagnosis names a withheld friction the file declares as an
//! effect. A file with a mistake is refused with its `path:line:column`, without a panic.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use stirling_dsl::Closure;

/// The default engine with the `nsection` gas, its bounce space closed in (a gas spring with
/// a heat port to the casing) and a linear alternator on the piston, with its EMF as a
/// sensor and the piston's Coulomb friction named as an effect (at its null).
const ENGINE: &str = r#"
/// Closed bounce space and a linear alternator on the family's nsection engine.
model Alternator extends nsection_engine {
    name "alternator_file";
    params {
        /// bounce-space volume at rest
        Vb0: 2.0e-3 "m^3",
        /// casing temperature
        Tb: 300.0 "K",
        /// alternator damping (the load)
        c_alt: 6.0 "N s/m",
        /// bounce-space wall area
        Awb: 0.06 "m^2",
        /// bounce-space heat-transfer coefficient
        hb: 20.0 "W/(m^2 K)",
        /// alternator EMF constant
        Kv: 25.0 "V s/m",
    }
    // friction only: the load is the alternator's
    replace params { bp: 1.9083 "N s/m" }
    modify body piston { force: -c_alt * w }
    remove space bounce;
    remove param Pb;
    cv bounce {
        volume: Vb0,
        faces { displacer: Ar, piston: A - Ar },
        port wall { h: hb, area: Awb, wall: Tb },
    }
    sensor p_bounce: P_bounce "Pa";
    sensor emf: Kv * w "V";
    effect coulomb on piston;
}
"#;

fn stirling(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .output()
        .expect("run stirling")
}

fn ok(args: &[&str]) -> String {
    let out = stirling(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_str(&ok(args)).unwrap_or_else(|e| panic!("{args:?}: not JSON: {e}"))
}

/// A fresh directory of this test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_engine_files")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn info_linearize_and_simulate_take_the_file() {
    let dir = scratch("analyses");
    let file = write(&dir, "alternator.stirling", ENGINE);
    let info = ok(&["info", &file, "--n", "2"]);
    // nsection at n = 2 has 12 states (full closure), the closed bounce space adds P_bounce
    assert!(
        info.starts_with("model alternator_file, n = 2, closure full: 13 states"),
        "{info}"
    );
    for needle in ["P_bounce", "c_alt", "Kv", "emf", "p_bounce", "Fc_piston"] {
        assert!(info.contains(needle), "missing `{needle}` in\n{info}");
    }
    // the bond graph of the file's topology, the closed bounce space in it
    let dot = ok(&["info", &file, "--n", "2", "--graph"]);
    assert!(dot.starts_with("digraph \"alternator_file\""), "{dot}");
    assert!(dot.contains("bounce"), "{dot}");
    // the poles from the command line are the file's model's through the Rust API
    let lin = json(&["linearize", &file, "--n", "2", "--json"]);
    assert_eq!(lin["model"], "alternator_file");
    assert_eq!(lin["n_states"], 13);
    let model = stirling_models::build(&file, Some(2), Closure::Full).unwrap();
    let p = model.default_params();
    let api = stirling_models::linear::linearize(model.as_ref(), &p, &Default::default())
        .expect("linearized");
    let poles = lin["poles"].as_array().unwrap();
    assert_eq!(poles.len(), api.dynamics.poles.len());
    for (cli, rust) in poles.iter().zip(&api.dynamics.poles) {
        let (re, im) = (cli["re"].as_f64().unwrap(), cli["im"].as_f64().unwrap());
        let d = ((re - rust.re).powi(2) + (im - rust.im).powi(2)).sqrt();
        assert!(
            d <= 1e-9 * (1.0 + rust.natural_rad_s),
            "{re} {im} vs {} {}",
            rust.re,
            rust.im
        );
    }
    // the engine runs: an unstable working pair near 14 Hz
    let (re, im) = (
        poles[0]["re"].as_f64().unwrap(),
        poles[0]["im"].as_f64().unwrap(),
    );
    assert!(re > 0.0 && (70.0..110.0).contains(&im.abs()), "{re} {im}");
    // `--model FILE` is the same as the path in the model's place
    let traj = dir.join("startup.csv");
    let traj = traj.to_str().unwrap();
    let sim = json(&[
        "simulate",
        "--n",
        "2",
        "--model",
        &file,
        "--t-end",
        "1",
        "--perturb",
        "2e-4",
        "--out",
        traj,
        "--json",
    ]);
    assert_eq!(sim["model"], "alternator_file");
    assert_eq!(sim["n_states"], 13);
    // from a 0.2 mm push, the start-up grows at the working pair's frequency
    let (t, x) = column(traj, "x");
    let amplitude = |from: f64, to: f64| {
        let w = (0..t.len()).filter(|&i| t[i] >= from && t[i] < to);
        w.map(|i| x[i].abs()).fold(0.0, f64::max)
    };
    let (early, late) = (amplitude(0.0, 0.2), amplitude(0.8, 1.0));
    assert!(late > 2.0 * early, "amplitude {early} -> {late}");
    let crossings: Vec<f64> = (1..t.len())
        .filter(|&i| t[i] >= 0.5 && x[i - 1] < 0.0 && x[i] >= 0.0)
        .map(|i| t[i])
        .collect();
    let hz = (crossings.len() - 1) as f64 / (crossings[crossings.len() - 1] - crossings[0]);
    let pole_hz = im.abs() / (2.0 * std::f64::consts::PI);
    assert!(
        (hz - pole_hz).abs() < 0.15 * pole_hz,
        "{hz} Hz, pole {pole_hz} Hz"
    );
}

/// The time and one column of a CSV written by `stirling simulate --out`.
fn column(path: &str, name: &str) -> (Vec<f64>, Vec<f64>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = head.iter().position(|h| *h == name).unwrap();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (
        rows.iter().map(|r| r[0]).collect(),
        rows.iter().map(|r| r[k]).collect(),
    )
}

#[test]
fn rig_fit_and_diagnose_take_the_file() {
    let dir = scratch("identification");
    let file = write(&dir, "alternator.stirling", ENGINE);
    let csv = dir.join("record.csv");
    let csv = csv.to_str().unwrap();
    let rig = |extra: &[&str], out: &str| {
        let base = ["rig", &file, "--n", "2", "--t-end", "2", "--rate", "1000"];
        let tail = ["--seed", "5", "--channels", "p,x,y,p_bounce", "--out", out];
        ok(&[&base[..], extra, &tail[..]].concat())
    };
    rig(&[], csv);
    let text = std::fs::read_to_string(csv).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    assert_eq!(header, "t,p,x,y,p_bounce");
    // the truth is the file's defaults: every free parameter inside its interval
    let fit = json(&["fit", &file, "--n", "2", "--data", csv, "--json"]);
    assert_eq!(fit["model"], "alternator_file");
    let model = stirling_models::build(&file, Some(2), Closure::Full).unwrap();
    let truth = model.default_params();
    let mut covered = 0;
    let mut fitted = 0;
    for stage in ["stage1", "stage2"] {
        for e in fit[stage]["stats"]["estimates"].as_array().unwrap() {
            if !e["model_param"].as_bool().unwrap() {
                continue;
            }
            let name = e["name"].as_str().unwrap();
            let k = model.param_index(name).unwrap();
            let (lo, hi) = (
                e["ci_low"].as_f64().unwrap(),
                e["ci_high"].as_f64().unwrap(),
            );
            fitted += 1;
            if lo <= truth[k] && truth[k] <= hi {
                covered += 1;
            } else {
                eprintln!("{name}: [{lo}, {hi}] misses {}", truth[k]);
            }
        }
    }
    // kd, kp, bd, bp, hh, hk, Rf declared free by default_engine
    assert_eq!(fitted, 7, "{fit}");
    assert!(
        covered >= 6,
        "{covered} of {fitted} intervals cover the truth"
    );
    // a withheld piston friction, the effect the file names, is what the diagnosis finds
    let fx = dir.join("friction.csv");
    let fx = fx.to_str().unwrap();
    rig(&["--effect", "Fc_piston=0.5"], fx);
    let args = ["diagnose", &file, "--n", "2", "--data", fx];
    let d = json(&[&args[..], &["--effects", "coulomb", "--json"]].concat());
    assert_eq!(d["verdict"]["verdict"], "effect", "{}", d["verdict"]);
    assert_eq!(d["verdict"]["effect"], "coulomb");
}

#[test]
fn a_mistake_in_the_file_is_refused_at_its_place() {
    let dir = scratch("mistake");
    let text = ENGINE.replace("sensor p_bounce: P_bounce", "sensor p_bounce: P_bounse");
    let file = write(&dir, "typo.stirling", &text);
    let line = text.lines().position(|l| l.contains("P_bounse")).unwrap() + 1;
    // fit and diagnose read their record first: a short one of the family's engine
    let csv = dir.join("record.csv");
    let csv = csv.to_str().unwrap();
    ok(&["rig", "nsection", "--t-end", "0.5", "--out", csv]);
    let out = dir.join("out.csv");
    for cmd in ["info", "linearize", "simulate", "fit", "diagnose", "rig"] {
        let mut args = vec![cmd, file.as_str()];
        match cmd {
            "fit" | "diagnose" => args.extend(["--data", csv]),
            "rig" => args.extend(["--out", out.to_str().unwrap()]),
            "simulate" => args.extend(["--t-end", "0.1"]),
            _ => {}
        }
        let out = stirling(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {err}");
        assert!(!err.contains("panicked"), "{cmd}: {err}");
        let place = format!("typo.stirling:{line}:22:");
        assert!(err.contains(&place), "{cmd}: no `{place}` in {err}");
        assert!(err.contains("P_bounse"), "{cmd}: {err}");
        assert!(err.contains('^'), "{cmd}: no caret in {err}");
    }
    // a path that is not there names it
    let out = stirling(&["info", "nowhere.stirling"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("nowhere.stirling"), "{err}");
}
