//! Options that would be silently ignored are refused, and the help points at the right
//! command.

mod support;

use support::{fails_with, stirling};

#[test]
fn graph_refuses_latex_and_json() {
    fails_with(
        &["info", "cv1", "--graph", "--latex"],
        &["--graph", "--latex", "cannot be used with"],
    );
    fails_with(
        &["info", "cv1", "--graph", "--json"],
        &["--graph", "--json", "cannot be used with"],
    );
}

#[test]
fn x0_help_points_at_info() {
    let out = stirling(&["simulate", "--help"]);
    let help = String::from_utf8(out.stdout).unwrap();
    assert!(help.contains("`stirling info MODEL`"), "{help}");
    assert!(!help.contains("see `stirling models`"), "{help}");
    let err = fails_with(
        &["simulate", "cv1", "--t-end", "1", "--x0", "0,0"],
        &["--x0 has 2 values"],
    );
    assert!(err.contains("see `stirling info cv1`"), "{err}");
}
