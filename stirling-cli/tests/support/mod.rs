//! Shared by the end-to-end tests: run the binary, expect a clear failure, scratch folders
//! and a small valid record.

#![allow(dead_code)]

pub mod python;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run `stirling` with `args`.
pub fn stirling(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .output()
        .expect("run stirling")
}

/// `args` succeed; their stderr.
pub fn succeeds(args: &[&str]) -> String {
    let out = stirling(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?} failed: {err}");
    err
}

/// `args` succeed; their stdout.
pub fn prints(args: &[&str]) -> String {
    let out = stirling(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("stdout is UTF-8")
}

/// `args` fail (non-zero exit, no panic) with every one of `needles` in stderr.
pub fn fails_with(args: &[&str], needles: &[&str]) -> String {
    let out = stirling(args);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in\n{err}");
    }
    err
}

/// A fresh, empty folder for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A path as `&str`.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A valid 1 s record (2 kHz, t,p,x,y) at `path`.
pub fn write_record(path: &Path) {
    let mut text = String::from("t,p,x,y\n");
    for k in 0..2000 {
        let t = k as f64 * 5e-4;
        let w = std::f64::consts::TAU * 10.0 * t;
        text.push_str(&format!(
            "{t},{},{},{}\n",
            1.0e6 + 1e4 * w.sin(),
            5e-3 * w.sin(),
            4e-3 * (w - 1.0).sin()
        ));
    }
    std::fs::write(path, text).unwrap();
}

/// A 2 s `cv1` rig record (settled 2 s) in `dir`, each data row's fields passed through
/// `row` (comment and header lines kept), written as `dir/name`.
pub fn edited_rig_record(
    dir: &Path,
    name: &str,
    row: impl Fn(Vec<&str>) -> Vec<String>,
) -> PathBuf {
    let rec = dir.join("rig.csv");
    succeeds(&[
        "rig",
        "cv1",
        "--settle",
        "2",
        "--t-end",
        "2",
        "--out",
        s(&rec),
    ]);
    let mut text = String::new();
    for line in std::fs::read_to_string(&rec).unwrap().lines() {
        if line.starts_with('#') || line.starts_with('t') {
            text.push_str(line);
        } else {
            text.push_str(&row(line.split(',').collect()).join(","));
        }
        text.push('\n');
    }
    let out = dir.join(name);
    std::fs::write(&out, text).unwrap();
    out
}
