//! The sparse state-space export read back by SciPy and python-control:
//! `linearize nsection --n 200 --json --ss FILE` (408 states, the sparse dominant route), then
//! `tests/python/sparse_poles.py` builds `A, B, C, D` of both loops from their triplets
//! (`scipy.sparse.coo_matrix`) and checks the printed poles against the matrices.
//!
//! The Python comes from `STIRLING_PYTHON` (as in `cli_python_control.rs`); missing, the test
//! fails: it is never skipped.

mod support;

use std::path::Path;
use std::process::Command;

use serde_json::Value;
use support::python::python;
use support::{s, scratch, stirling};

/// `--json --ss FILE` at `n`: the report (stdout) saved next to FILE; both paths.
fn export(name: &str, n: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = scratch(name);
    let (ss, report) = (dir.join("ss.json"), dir.join("report.json"));
    let out = stirling(&["linearize", "nsection", "--n", n, "--json", "--ss", s(&ss)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    std::fs::write(&report, &out.stdout).unwrap();
    (ss, report)
}

fn f(v: &Value, path: &[&str]) -> f64 {
    let x = path.iter().fold(v, |v, k| &v[*k]);
    x.as_f64()
        .unwrap_or_else(|| panic!("{} missing in {v}", path.join(".")))
}

#[test]
fn scipy_finds_the_printed_poles_in_the_sparse_matrices() {
    let py = python();
    let (ss, report) = export("python_sparse_poles", "200");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/sparse_poles.py");
    let out = Command::new(&py)
        .arg(&script)
        .args([&ss, &report])
        .output()
        .expect("run python");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{} failed: {err}", script.display());
    let m: Value = serde_json::from_slice(&out.stdout).expect("sparse_poles.py prints JSON");
    for l in ["broken", "closed"] {
        let shapes = &m[l]["shapes"];
        assert_eq!(
            shapes.to_string(),
            "[[407,407],[407,1],[1,407],[1,1]]",
            "{m}"
        );
        assert_eq!(m[l]["poles"], 5, "the five dominant poles ({m})");
        // every printed pole is an eigenvalue of the exported A to 1e-8 relative
        let rel = f(&m, &[l, "shift_invert_rel"]);
        assert!(rel <= 1e-8, "{l}: shift-invert {rel:e} ({m})");
        // and they are the rightmost: no other eigenvalue between them and the imaginary axis
        assert_eq!(m[l]["rightmost_count"], 5, "{m}");
        // python-control's dense eig of the same A: to the dense eig's accuracy on this
        // badly scaled matrix (pressures in Pa next to masses in kg)
        let ctl = f(&m, &[l, "control_rel"]);
        assert!(ctl <= 1e-6, "{l}: control.ss poles {ctl:e} ({m})");
        // 407 states: the dense fields are written too and equal the triplets
        assert_eq!(f(&m, &[l, "dense_vs_sparse"]), 0.0, "{m}");
    }
    let bc = f(&m, &["closed_minus_a0_bc"]);
    assert!(bc <= 1e-12, "closed = broken - B C to {bc:e} ({m})");
    let bode = f(&m, &["bode_rel"]);
    assert!(
        bode <= 1e-8,
        "|L(jw)| against the file's Bode data: {bode:e} ({m})"
    );
}

#[test]
fn the_report_and_the_file_agree_on_the_poles() {
    let (ss, report) = export("python_sparse_agree", "200");
    let e: Value = serde_json::from_str(&std::fs::read_to_string(ss).unwrap()).unwrap();
    let r: Value = serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    assert_eq!(e, r["state_space"], "--ss writes what --json carries");
    for (table, poles) in [
        ("closed_loop", &r["poles"]),
        ("broken_loop", &r["loop"]["open_loop_poles"]),
    ] {
        let damp = e[table]["poles"].as_array().unwrap();
        let want = poles.as_array().unwrap();
        assert_eq!(damp.len(), want.len());
        for (d, p) in damp.iter().zip(want) {
            assert_eq!((&d["re"], &d["im"]), (&p["re"], &p["im"]));
        }
    }
    for m in ["a", "b", "c", "d"] {
        let t = &e["closed_loop"][format!("{m}_sparse")];
        assert!(
            t["format"]
                .as_str()
                .unwrap()
                .starts_with("triplets, 0-based"),
            "{t}"
        );
    }
}
