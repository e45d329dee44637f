//! A reader that stops early (`stirling ... | head`) closes stdout: every command then ends
//! quietly (exit 0, no panic, no backtrace), whatever it was printing.

use std::process::{Command, Stdio};

/// Run with stdout closed before the program writes anything.
fn closed_stdout(args: &[&str]) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run stirling");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("wait for stirling");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("Broken pipe") && !err.contains("error"),
        "{args:?}: stderr `{err}`"
    );
    assert!(
        out.status.success(),
        "{args:?}: {:?}, stderr `{err}`",
        out.status
    );
}

#[test]
fn models_ends_quietly() {
    closed_stdout(&["models", "--json"]);
    closed_stdout(&["models"]);
}

#[test]
fn linearize_ends_quietly() {
    closed_stdout(&["linearize", "schmidt"]);
    closed_stdout(&["linearize", "schmidt", "--json"]);
}

#[test]
fn simulate_ends_quietly() {
    closed_stdout(&["simulate", "schmidt", "--t-end", "0.02", "--json"]);
    closed_stdout(&["simulate", "schmidt", "--t-end", "0.02"]);
}

#[test]
fn info_and_locus_end_quietly() {
    closed_stdout(&["info", "cv2"]);
    closed_stdout(&["info", "cv1", "--graph"]);
    closed_stdout(&["info", "cv1", "--json"]);
    let locus = [
        "locus", "schmidt", "--param", "Th", "--from", "500", "--to", "700", "--steps", "3",
    ];
    closed_stdout(&locus);
}

#[test]
fn help_ends_quietly() {
    closed_stdout(&["--help"]);
}
