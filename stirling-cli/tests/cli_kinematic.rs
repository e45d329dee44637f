//! The kinematic engines of `examples/engines/` from the command line: `info` lists the
//! flywheel's states in rad and rad/s and `--graph` draws each face on a crank as an MTF;
//! `simulate` runs one from a push (`--x0`) and it keeps turning; `--limit-cycle`, which shoots a closed orbit of every
//! state, is refused by name (the flywheel's angle grows a revolution at a time).

mod support;

use std::path::PathBuf;

use support::{prints as ok, stirling};

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
fn info_lists_the_flywheel_and_draws_the_cranks_as_mtf() {
    let gamma = engine("gamma_ltd.stirling");
    let info = ok(&["info", &gamma]);
    assert!(
        info.contains("theta   rad    angle of the flywheel wheel"),
        "{info}"
    );
    assert!(
        info.contains("omega   rad/s  angular velocity of the flywheel wheel"),
        "{info}"
    );
    let graph = ok(&["info", &gamma, "--graph"]);
    assert_eq!(graph.matches("label=\"MTF: ").count(), 4, "{graph}");
    assert!(graph.contains("MTF: -Ap * ds_piston(theta)"), "{graph}");
}

#[test]
fn simulate_runs_from_a_push_and_refuses_the_limit_cycle() {
    let beta = engine("beta.stirling");
    // the rest state (`equilibrium_guess`) with the flywheel pushed to 5 Hz
    let m =
        stirling_models::files::build(std::path::Path::new(&beta), 1, stirling_dsl::Closure::Full)
            .unwrap();
    let p = m.default_params();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[1] = 10.0 * std::f64::consts::PI;
    let x0: Vec<String> = x0.iter().map(|v| format!("{v:e}")).collect();
    let out = ok(&["simulate", &beta, "--t-end", "3", "--x0", &x0.join(",")]);
    let last = out
        .lines()
        .find_map(|l| l.strip_prefix("final state: "))
        .unwrap_or_else(|| panic!("{out}"));
    let state: Vec<f64> = last
        .split(", ")
        .map(|v| v.trim().parse().unwrap())
        .collect();
    // it keeps turning forward, near its steady 6 Hz (38 rad/s)
    assert!(state[0] > 2.0 * 2.0 * std::f64::consts::PI * 3.0, "{out}");
    assert!((30.0..45.0).contains(&state[1]), "{out}");
    let out = stirling(&["simulate", &beta, "--t-end", "2", "--limit-cycle"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("the flywheel's angle `theta` grows by 2 pi a revolution"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// The kinematic base is built in: `stirling models` lists it among the bases and the
/// kinematic engines' files with their summaries, and a copy of the gamma engine's file in a
/// folder of its own (no `bases/` beside it) loads and runs.
#[test]
fn the_kinematic_base_is_built_in() {
    let models = ok(&["models"]);
    assert!(
        models.contains("kinematic_engine") && models.contains("nsection_engine"),
        "{models}"
    );
    for (file, summary) in [
        ("gamma_ltd.stirling", "Gamma-type LTD engine"),
        ("beta.stirling", "Beta-type engine"),
        ("alpha.stirling", "Alpha-type engine"),
    ] {
        assert!(
            models.contains(&format!("examples/engines/{file}")) && models.contains(summary),
            "{file}: {models}"
        );
    }
    let dir = support::scratch("kinematic_copy");
    let copy = dir.join("my_ltd.stirling");
    std::fs::copy(engine("gamma_ltd.stirling"), &copy).unwrap();
    let info = ok(&["info", support::s(&copy)]);
    assert!(info.contains("theta") && info.contains("omega"), "{info}");
}

/// The gamma engine's rig record as a lab logs it - `t [ms]`, `p [kPa gauge]`, `theta [deg]`
/// at 100 Hz after a push start - fitted from the command line: stage 2 drives the gas with
/// the measured angle and every 95 % interval covers the truth (`Rf` x2, `Gleak` x3); a
/// record without the angle and one too short are refused by name, and so are the defaults'
/// free flywheel parameters.
#[test]
fn a_lab_record_of_the_gamma_engine_is_fitted_from_the_command_line() {
    let gamma = engine("gamma_ltd.stirling");
    let dir = support::scratch("kinematic_fit");
    let rig = dir.join("rig.csv");
    let rig_args = |channels: &str, out: &std::path::Path| {
        let mut a = vec![
            "rig",
            &gamma,
            "--set",
            "Rf=2e4",
            "--set",
            "Gleak=1.2e-9",
            "--start",
            "omega=17.7",
            "--settle",
            "5",
            "--t-end",
            "10",
            "--rate",
            "100",
            "--noise-p",
            "10",
            "--seed",
            "7",
            "--channels",
            channels,
            "--force",
            "--out",
        ];
        a.push(support::s(out));
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let args = {
        let mut a = rig_args("p,theta", &rig);
        a.extend(["--noise".into(), "theta=0.002".into()]);
        a
    };
    let wrote = ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(
        wrote.contains("1001 samples, channels t,p,theta"),
        "{wrote}"
    );
    // as the lab logs it: milliseconds, kPa over the room, degrees
    let mut lab = String::from("t [ms],p [kPa gauge],theta [deg]\n");
    for line in std::fs::read_to_string(&rig).unwrap().lines() {
        let v: Vec<f64> = match line.split(',').map(str::parse).collect() {
            Ok(v) => v,
            Err(_) => continue, // comments and the header
        };
        lab.push_str(&format!(
            "{},{},{}\n",
            v[0] * 1e3,
            (v[1] - 101_325.0) / 1e3,
            v[2].to_degrees()
        ));
    }
    let rec = dir.join("lab.csv");
    std::fs::write(&rec, &lab).unwrap();
    let free = "--free=hp,hs,Rf,Gleak";
    let out = ok(&["fit", &gamma, "--data", support::s(&rec), free, "--json"]);
    let id: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let truth = [("hp", 40.0), ("hs", 10.0), ("Rf", 2e4), ("Gleak", 1.2e-9)];
    let est = id["stage2"]["stats"]["estimates"]
        .as_array()
        .expect("stage 2");
    for (name, t) in truth {
        let e = est.iter().find(|e| e["name"] == name).expect(name);
        let (lo, hi) = (
            e["ci_low"].as_f64().unwrap(),
            e["ci_high"].as_f64().unwrap(),
        );
        assert!(lo <= t && t <= hi, "{name}: [{lo}, {hi}] misses {t}");
    }
    assert!(id["stage1"].is_null(), "{out}");
    // an encoder's counter wrapping at 360 degrees is unwrapped before the outliers are looked
    // for (a wrap is a step, not a spike): the same estimates
    let wrapped: String = lab
        .lines()
        .map(|l| match l.rsplit_once(',') {
            Some((head, a)) => match a.parse::<f64>() {
                Ok(v) => format!("{head},{}\n", v.rem_euclid(360.0)),
                Err(_) => format!("{l}\n"),
            },
            None => format!("{l}\n"),
        })
        .collect();
    let wrec = dir.join("wrapped.csv");
    std::fs::write(&wrec, wrapped).unwrap();
    let wout = ok(&[
        "fit",
        &gamma,
        "--data",
        support::s(&wrec),
        free,
        "--json",
        "--drop-outliers",
    ]);
    let wid: serde_json::Value = serde_json::from_str(&wout).expect("JSON");
    let west = wid["stage2"]["stats"]["estimates"]
        .as_array()
        .expect("stage 2");
    // the model parameters (the two initial masses, correlated at -0.99, move together
    // along their ridge by a few tenths of their error)
    for (e, w) in est.iter().zip(west).take(truth.len()) {
        let (a, b) = (e["value"].as_f64().unwrap(), w["value"].as_f64().unwrap());
        let se = e["std_error"].as_f64().unwrap();
        assert!((a - b).abs() <= 0.1 * se, "{}: {a} vs {b}", e["name"]);
    }
    // refused: no angle, too few samples, a Coulomb torque and a load both freed
    let p_only = dir.join("p_only.csv");
    let args = rig_args("p", &p_only);
    ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    support::fails_with(
        &["fit", &gamma, "--data", support::s(&p_only), free],
        &[
            "a kinematic engine needs the flywheel's angle `theta`",
            "no column `theta`",
        ],
    );
    let short = dir.join("short.csv");
    std::fs::write(&short, lab.lines().take(16).collect::<Vec<_>>().join("\n")).unwrap();
    support::fails_with(
        &["fit", &gamma, "--data", support::s(&short), free],
        &["15 samples are too few to fit"],
    );
    support::fails_with(
        &[
            "fit",
            &gamma,
            "--data",
            support::s(&rec),
            "--free",
            "hp,Tc,Tl",
        ],
        &["`Tc, Tl` of `gamma_ltd` cannot be told apart", "free one"],
    );
    // the defaults (the declared `free cf, Tc`): the flywheel's torque balance
    let out = ok(&["fit", &gamma, "--data", support::s(&rec)]);
    assert!(
        out.contains("flywheel's torque balance") && out.contains("T_friction"),
        "{out}"
    );
    // the diagnosis runs on it (its candidates: the effects the file names), and says why
    // no simulated gap; a record sampled below 10 samples a revolution is refused by its
    // rate, not as a still pressure
    let out = ok(&["diagnose", &gamma, "--data", support::s(&rec)]);
    assert!(out.contains("\nverdict: "), "{out}");
    for part in [
        "leak",
        "quadratic",
        "lag",
        "not computed on a kinematic engine",
    ] {
        assert!(out.contains(part), "{part}: {out}");
    }
    let slow = dir.join("slow.csv");
    ok(&[
        "rig",
        &gamma,
        "--start",
        "omega=17.7",
        "--settle",
        "5",
        "--t-end",
        "5",
        "--rate",
        "20",
        "--out",
        support::s(&slow),
    ]);
    let head = std::fs::read_to_string(&slow).unwrap();
    assert!(head.lines().any(|l| l.starts_with("t,p,theta")), "{head}");
    for cmd in ["fit", "diagnose"] {
        support::fails_with(
            &[cmd, &gamma, "--data", support::s(&slow), "--free", "hp,hs"],
            &["samples per revolution", "at least 10 samples a revolution"],
        );
    }
    // the rig's push names a state
    support::fails_with(
        &[
            "rig",
            &gamma,
            "--channels",
            "p",
            "--start",
            "speed=3",
            "--out",
            support::s(&dir.join("no.csv")),
        ],
        &[
            "--start names `speed`, which is not a state of `gamma_ltd`",
            "omega",
        ],
    );
}
