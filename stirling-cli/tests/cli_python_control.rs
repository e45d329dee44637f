//! The state-space export read by python-control: `linearize schmidt --ss FILE`, then
//! `control.ss(A, B, C, D)` and `control.margin` on the broken loop give the seed's margins
//! (Gm -6.63 dB at 81.6 rad/s, Pm -79.5 deg at 91.3 rad/s).
//!
//! The Python comes from `STIRLING_PYTHON` (`.ci/run` exports its virtual environment's);
//! without it, `python3` must import `control`. A missing python-control fails the test: it
//! is never skipped.

mod support;

use std::path::Path;
use std::process::Command;

use serde_json::Value;
use support::python::python;
use support::{s, scratch, succeeds};

#[test]
fn python_control_reads_the_seed_margins_of_schmidt() {
    let py = python();
    let dir = scratch("python_control");
    let f = dir.join("schmidt.json");
    succeeds(&["linearize", "schmidt", "--ss", s(&f)]);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/margins.py");
    let out = Command::new(&py)
        .arg(&script)
        .arg(&f)
        .output()
        .expect("run python");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{} failed: {err}", script.display());
    let m: Value = serde_json::from_slice(&out.stdout).expect("margins.py prints JSON");
    let get = |k: &str| {
        m[k].as_f64()
            .unwrap_or_else(|| panic!("{k} missing in {m}"))
    };
    let (gm, w_pc, pm, w_gc) = (get("gm_db"), get("w_pc"), get("pm_deg"), get("w_gc"));
    assert!((gm + 6.63).abs() <= 0.05, "Gm = {gm} dB, want -6.63 ({m})");
    assert!(
        (w_pc - 81.6).abs() <= 0.05,
        "phase crossover {w_pc} rad/s, want 81.6 ({m})"
    );
    assert!((pm + 79.5).abs() <= 0.5, "Pm = {pm} deg, want -79.5 ({m})");
    assert!(
        (w_gc - 91.3).abs() <= 0.05,
        "gain crossover {w_gc} rad/s, want 91.3 ({m})"
    );
}
