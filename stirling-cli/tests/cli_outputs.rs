//! One rule for every file the command line writes: an existing file is refused without
//! `--force` (non-zero exit, the message names it, the file is unchanged), missing folders are
//! created, and each file written is named on stderr.

mod support;

use std::path::Path;

use support::{fails_with, s, scratch, succeeds, write_record};

const MARK: &str = "keep me";

/// Put a marked file at `path`.
fn existing(path: &Path) {
    std::fs::write(path, MARK).unwrap();
}

fn unchanged(path: &Path) {
    assert_eq!(
        std::fs::read_to_string(path).unwrap(),
        MARK,
        "{}",
        path.display()
    );
}

#[test]
fn simulate_out_is_kept() {
    let dir = scratch("out_kept");
    let f = dir.join("traj.csv");
    existing(&f);
    let sim = ["simulate", "schmidt", "--t-end", "0.01", "--out", s(&f)];
    fails_with(&sim, &["--out", s(&f), "exists", "--force"]);
    unchanged(&f);
}

#[test]
fn out_creates_missing_folders_and_says_so() {
    let dir = scratch("out_folders");
    let f = dir.join("a").join("b").join("traj.csv");
    let err = succeeds(&[
        "simulate",
        "schmidt",
        "--t-end",
        "0.01",
        "--samples",
        "11",
        "--out",
        s(&f),
    ]);
    assert!(err.contains(&format!("wrote {}", f.display())), "{err}");
    let text = std::fs::read_to_string(&f).unwrap();
    assert_eq!(
        text.lines().count(),
        12,
        "a header and the 11 samples asked for"
    );
    let g = dir.join("x").join("cv1.dot");
    let err = succeeds(&["info", "cv1", "--graph", "--out", s(&g)]);
    assert!(err.contains(&format!("wrote {}", g.display())), "{err}");
}

#[test]
fn out_that_is_a_folder_is_refused() {
    let dir = scratch("out_folder");
    let sim = ["simulate", "schmidt", "--t-end", "0.01", "--out", s(&dir)];
    fails_with(&sim, &["--out", "is a folder"]);
}

#[test]
fn plot_figures_are_kept() {
    let dir = scratch("plot_kept");
    for (args, figure) in [
        (vec!["linearize", "schmidt"], "bode.svg"),
        (
            vec!["simulate", "schmidt", "--t-end", "0.01"],
            "startup.svg",
        ),
        (
            vec![
                "locus", "schmidt", "--param", "Th", "--from", "500", "--to", "600", "--steps", "2",
            ],
            "locus.svg",
        ),
        (vec!["fit", "cv1", "--data", "no.csv"], "stage1_p.svg"),
    ] {
        let f = dir.join(figure);
        existing(&f);
        let args: Vec<&str> = args.into_iter().chain(["--plot", s(&dir)]).collect();
        fails_with(&args, &["--plot", s(&f), "--force"]);
        unchanged(&f);
        std::fs::remove_file(&f).unwrap();
    }
}

#[test]
fn diagnose_report_is_kept() {
    let dir = scratch("report_kept");
    let f = dir.join("report.md");
    existing(&f);
    let args = ["diagnose", "cv1", "--data", "no.csv", "--report", s(&dir)];
    fails_with(&args, &["--report", s(&f), "--force"]);
    unchanged(&f);
}

#[test]
fn plot_creates_names_and_overwrites_with_force() {
    let dir = scratch("plot_force").join("new");
    let err = succeeds(&["linearize", "schmidt", "--plot", s(&dir)]);
    for f in ["poles.svg", "bode.svg"] {
        assert!(
            err.contains(&format!("wrote {}", dir.join(f).display())),
            "{err}"
        );
    }
    fails_with(
        &["linearize", "schmidt", "--plot", s(&dir)],
        &["poles.svg", "bode.svg"],
    );
    succeeds(&["linearize", "schmidt", "--plot", s(&dir), "--force"]);
}

#[test]
fn plot_that_is_a_file_is_refused() {
    let dir = scratch("plot_file");
    let f = dir.join("plots");
    existing(&f);
    fails_with(
        &["linearize", "schmidt", "--plot", s(&f)],
        &["--plot", "is a file"],
    );
    unchanged(&f);
}

#[test]
fn training_and_held_out_blocks_are_ordered() {
    let dir = scratch("blocks");
    let data = dir.join("rec.csv");
    write_record(&data);
    let d = s(&data);
    for (cmd, extra, needles) in [
        (
            "fit",
            ["--train", "0:0.6", "--holdout", "0.5:1"],
            vec!["--holdout 0.5:1 overlaps --train 0:0.6"],
        ),
        (
            "fit",
            ["--train", "0.5:1", "--holdout", "0:0.4"],
            vec!["--holdout 0:0.4 comes before --train 0.5:1"],
        ),
        (
            "diagnose",
            ["--train", "0:0.6", "--holdout", "0.2:0.8"],
            vec!["overlaps --train 0:0.6"],
        ),
        (
            "fit",
            ["--train", "0:5", "--holdout", "0.5:1"],
            vec!["--train 0:5", "outside the record", "0.9995"],
        ),
        (
            "fit",
            ["--train", "0.6:0.2", "--holdout", "0.7:1"],
            vec!["--train 0.6:0.2", "empty"],
        ),
        (
            "fit",
            ["--holdout", "0:0.3", "--n", "1"],
            vec!["--holdout 0:0.3", "default training block 0:0.69965"],
        ),
    ] {
        let args: Vec<&str> = [cmd, "cv1", "--data", d].into_iter().chain(extra).collect();
        fails_with(&args, &needles);
    }
}
