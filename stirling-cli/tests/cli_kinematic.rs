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

/// The kinematic base is built in: `stirling models` lists it among the bases, and a copy of
/// the gamma engine's file in a folder of its own (no `bases/` beside it) loads and runs.
#[test]
fn the_kinematic_base_is_built_in() {
    let models = ok(&["models"]);
    assert!(
        models.contains("kinematic_engine") && models.contains("nsection_engine"),
        "{models}"
    );
    let dir = support::scratch("kinematic_copy");
    let copy = dir.join("my_ltd.stirling");
    std::fs::copy(engine("gamma_ltd.stirling"), &copy).unwrap();
    let info = ok(&["info", support::s(&copy)]);
    assert!(info.contains("theta") && info.contains("omega"), "{info}");
}
