//! Memory without bound (issue 38): a record whose rows would take more than the limit is
//! refused after its first rows, with the estimate and the next step; with `--train` and
//! `--holdout` only the rows of the blocks are kept, so the same file reads; one sweep axis
//! with a billion values is refused before its values are made.

mod support;

use std::process::Command;

use support::{fails_with, s, scratch};

/// A moving record of `rows` samples at 2 kHz (13.4 Hz, t,p,x,y).
fn long_record(name: &str, rows: usize) -> std::path::PathBuf {
    let f = scratch(name).join("long.csv");
    let mut text = String::with_capacity(rows * 64);
    text.push_str("t,p,x,y\n");
    for k in 0..rows {
        let t = k as f64 * 5e-4;
        let w = (std::f64::consts::TAU * 13.4 * t).sin();
        let v = (std::f64::consts::TAU * 13.4 * t + 1.4).sin();
        text.push_str(&format!(
            "{t},{:.1},{:.6},{:.6}\n",
            101325.0 + 5800.0 * w,
            0.0079 * v,
            0.0062 * w
        ));
    }
    std::fs::write(&f, text).unwrap();
    f
}

/// `stirling args` with the record limit set to `mb`; (success, stderr).
fn with_limit(mb: &str, args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .env("STIRLING_MAX_RECORD_MB", mb)
        .output()
        .expect("run stirling");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    (out.status.success(), err)
}

#[test]
fn a_record_past_the_memory_limit_is_refused_up_front_with_the_next_step() {
    // 200 000 rows (100 s at 2 kHz): about 400 MB for a fit, against a limit of 50 MB
    let f = long_record("mem_whole", 200_000);
    for cmd in ["fit", "diagnose"] {
        let (ok, err) = with_limit("50", &[cmd, "cv1", "--data", s(&f)]);
        assert!(!ok, "{cmd} read the whole record");
        for needle in [
            "the record holds about",
            "more than the limit of 50 MB",
            "give --train and --holdout",
            "STIRLING_MAX_RECORD_MB",
            "row 1001",
        ] {
            assert!(err.contains(needle), "{cmd}: `{needle}` not in\n{err}");
        }
    }
    // the blocks asked for (1.5 s of 100 s) fit the same limit: the reader keeps only them,
    // and the command goes on to its next check (here an unknown parameter)
    let (ok, err) = with_limit(
        "50",
        &[
            "fit",
            "cv1",
            "--data",
            s(&f),
            "--train",
            "0:1",
            "--holdout",
            "1:1.5",
            "--free",
            "nosuch",
        ],
    );
    assert!(!ok);
    assert!(!err.contains("limit of"), "{err}");
    assert!(err.contains("nosuch"), "{err}");
    // blocks that are themselves too large are refused the same way
    let (ok, err) = with_limit(
        "50",
        &[
            "fit",
            "cv1",
            "--data",
            s(&f),
            "--train",
            "0:60",
            "--holdout",
            "60:90",
        ],
    );
    assert!(!ok);
    assert!(err.contains("the blocks asked for hold about"), "{err}");
}

#[test]
fn blocks_outside_a_windowed_record_are_named_with_the_record_span() {
    let f = long_record("mem_outside", 4000);
    fails_with(
        &[
            "fit",
            "cv1",
            "--data",
            s(&f),
            "--train",
            "10:11",
            "--holdout",
            "11:12",
        ],
        &["record runs from 0 s to 1.9995 s", "inside the record"],
    );
}

#[test]
fn one_sweep_axis_of_a_billion_values_is_refused_before_it_is_made() {
    let dir = scratch("mem_sweep");
    fails_with(
        &[
            "sweep",
            "cv1",
            "--grid",
            "Th=500:700:1000000000",
            "--poles-only",
            "--out",
            s(&dir.join("out")),
        ],
        &["1000000000 values on one axis", "more than the 10000000"],
    );
}
