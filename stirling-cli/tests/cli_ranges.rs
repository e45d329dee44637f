//! Numeric options out of range: a non-zero exit and a message naming the option and the
//! value, before any work; negative numbers reach the range check (not clap's "unexpected
//! argument" tip).

mod support;

use support::{fails_with, s, scratch};

/// `args` fail naming `option` and `value`, with `why`.
fn refused(args: &[&str], option: &str, value: &str, why: &str) {
    let err = fails_with(args, &[option, &format!("'{value}'"), why]);
    assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
}

#[test]
fn tolerances() {
    // 1e-30 ended in "step size collapsed ... the solution is singular", blaming the model
    for v in ["1", "-1", "0", "0.5", "1e-30"] {
        refused(
            &["simulate", "schmidt", "--t-end", "1", "--rtol", v],
            "--rtol",
            v,
            "[1e-14, 0.1]",
        );
        refused(
            &["simulate", "schmidt", "--t-end", "1", "--atol", v],
            "--atol",
            v,
            "[1e-14, 0.1]",
        );
    }
    refused(
        &["simulate", "schmidt", "--t-end", "1", "--rtol", "nan"],
        "--rtol",
        "nan",
        "finite",
    );
}

#[test]
fn samples() {
    for v in ["0", "1", "-5", "1e8", "2.5"] {
        refused(
            &["simulate", "schmidt", "--t-end", "1", "--samples", v],
            "--samples",
            v,
            "",
        );
    }
    refused(
        &["simulate", "schmidt", "--t-end", "1", "--samples", "1e8"],
        "--samples",
        "1e8",
        "between 2 and 1000000",
    );
}

#[test]
fn huge_output_is_refused_before_writing() {
    let dir = scratch("huge");
    let f = dir.join("big.csv");
    let args = [
        "simulate",
        "nsection",
        "--n",
        "30",
        "--t-end",
        "1",
        "--samples",
        "1e6",
        "--out",
        s(&f),
    ];
    fails_with(
        &args,
        &[
            "--out",
            "1000000 samples of 69 columns",
            "GB",
            "lower --samples",
        ],
    );
    assert!(!f.exists());
}

#[test]
fn end_times_and_rates() {
    for v in ["-1", "0", "inf"] {
        refused(&["simulate", "schmidt", "--t-end", v], "--t-end", v, "");
        refused(
            &["diagnose", "--self-check", "--t-end", v],
            "--t-end",
            v,
            "",
        );
        refused(&["diagnose", "--self-check", "--rate", v], "--rate", v, "");
    }
    refused(
        &["simulate", "schmidt", "--t-end", "-1"],
        "--t-end",
        "-1",
        "> 0",
    );
    refused(
        &["diagnose", "--self-check", "--strengths", "1,-2"],
        "--strengths",
        "-2",
        "> 0",
    );
    fails_with(
        &["diagnose", "--self-check", "--prior", "-1"],
        &["--prior", "-1", ">= 0"],
    );
}

#[test]
fn counts() {
    for v in ["-1", "0", "1.5"] {
        refused(&["linearize", "nsection", "--n", v], "--n", v, "");
        refused(
            &["simulate", "nsection", "--n", v, "--t-end", "1"],
            "--n",
            v,
            "",
        );
        refused(&["fit", "cv1", "--data", "r.csv", "--n", v], "--n", v, "");
        refused(
            &["diagnose", "cv1", "--data", "r.csv", "--n", v],
            "--n",
            v,
            "",
        );
        let locus = [
            "locus", "schmidt", "--param", "Th", "--from", "1", "--to", "2", "--steps", v,
        ];
        refused(&locus, "--steps", v, "");
    }
    refused(
        &["linearize", "nsection", "--n", "-1"],
        "--n",
        "-1",
        "must be at least 1",
    );
}

#[test]
fn multiple_shooting_and_finite_values() {
    for v in ["-1", "0", "0.5", "nan"] {
        let fit = ["fit", "cv1", "--data", "r.csv", "--multiple-shooting", v];
        refused(&fit, "--multiple-shooting", v, "");
    }
    for v in ["-1", "0", "1e9", "nan"] {
        let fit = ["fit", "cv1", "--data", "r.csv", "--restart-cycles", v];
        refused(&fit, "--restart-cycles", v, "");
        let diagnose = [
            "diagnose",
            "nsection",
            "--data",
            "r.csv",
            "--restart-cycles",
            v,
        ];
        refused(&diagnose, "--restart-cycles", v, "");
    }
    let locus = [
        "locus", "schmidt", "--param", "Th", "--from", "nan", "--to", "2",
    ];
    refused(&locus, "--from", "nan", "finite");
    refused(
        &["simulate", "schmidt", "--t-end", "1", "--perturb", "inf"],
        "--perturb",
        "inf",
        "finite",
    );
    fails_with(
        &["simulate", "schmidt", "--t-end", "1", "--x0", "0,0,nan,0"],
        &["--x0", "`nan`", "finite"],
    );
}

#[test]
fn rig_negative_values_reach_the_range_check() {
    let dir = scratch("rig_ranges");
    let out = dir.join("r.csv");
    let rig = |extra: &[&'static str]| -> Vec<String> {
        ["rig", "cv1", "--out", s(&out)]
            .iter()
            .map(|a| a.to_string())
            .chain(extra.iter().map(|a| a.to_string()))
            .collect()
    };
    let run = |extra: &[&'static str], needles: &[&str]| {
        let args = rig(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let err = fails_with(&args, needles);
        assert!(!err.contains("unexpected argument"), "{args:?}: {err}");
    };
    run(&["--t-end", "-1"], &["--t-end", "-1"]);
    run(&["--rate", "-5"], &["--rate", "-5"]);
    run(&["--settle", "-1"], &["--settle", "-1"]);
    run(&["--noise-p", "-1"], &["--noise-p", "-1"]);
    run(&["--n", "-1"], &["'--n <N>': must be at least 1"]);
    run(&["--offset-p", "nan"], &["--offset-p", "finite"]);
    run(&["--noise", "x=-1"], &["--noise", ">= 0"]);
    run(&["--noise", "x"], &["--noise", "CHANNEL=SD"]);
    // a channel's noise for a channel not written is a typo, not silently ignored
    run(
        &["--noise", "p_hot=10"],
        &["--noise names `p_hot`", "--channels p,x,y"],
    );
    assert!(!out.exists());
}
