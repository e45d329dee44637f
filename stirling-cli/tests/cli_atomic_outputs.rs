//! Outputs are written whole or not at all (issue 38, "half-written files"): a run
//! interrupted by Ctrl-C leaves no CSV cut mid-row, and two runs writing one record at once
//! leave one run's CSV with that same run's truth sidecar, never a mix or interleaved rows.

mod support;

use std::process::{Command, Stdio};
use std::time::Duration;

use support::{s, scratch, succeeds};

fn stirling() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stirling"))
}

/// The data rows of a CSV: every one must have as many fields as its header.
fn rows(text: &str) -> usize {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let fields = lines.next().expect("a header").split(',').count();
    let data: Vec<&str> = lines.collect();
    for (i, l) in data.iter().enumerate() {
        assert_eq!(l.split(',').count(), fields, "row {i} is cut or mixed: {l}");
    }
    data.len()
}

#[test]
fn an_interrupted_simulation_leaves_no_cut_file() {
    let dir = scratch("atomic_sigint");
    let out = dir.join("f.csv");
    for wait_ms in [300u64, 1200, 2500] {
        let _ = std::fs::remove_file(&out);
        let mut child = stirling()
            .args([
                "simulate",
                "cv1",
                "--t-end",
                "3",
                "--samples",
                "400000",
                "--out",
                s(&out),
            ])
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(wait_ms));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let status = child.wait().unwrap();
        if out.exists() {
            // finished before the signal: then it is whole
            assert!(status.success(), "a file was left by a failed run");
            let text = std::fs::read_to_string(&out).unwrap();
            assert_eq!(rows(&text), 400000);
        }
    }
    // the next run is not refused because of an earlier interrupted one
    let _ = std::fs::remove_file(&out);
    succeeds(&[
        "simulate",
        "cv1",
        "--t-end",
        "0.2",
        "--samples",
        "50",
        "--out",
        s(&out),
    ]);
    assert_eq!(rows(&std::fs::read_to_string(&out).unwrap()), 50);
}

#[test]
fn two_rigs_on_one_path_never_mix_their_files() {
    let dir = scratch("atomic_concurrent");
    let out = dir.join("same.csv");
    let run = |seed: &str| {
        stirling()
            .args([
                "rig",
                "cv1",
                "--t-end",
                "1",
                "--seed",
                seed,
                "--force",
                "--out",
                s(&out),
            ])
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (run("1"), run("2"));
    let outs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
    let ok = outs.iter().filter(|o| o.status.success()).count();
    assert!(ok >= 1, "neither run wrote the record");
    for o in outs.iter().filter(|o| !o.status.success()) {
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("another run is writing"), "{err}");
    }
    let csv = std::fs::read_to_string(&out).unwrap();
    assert_eq!(rows(&csv), 2001, "1 s at 2 kHz, both ends");
    let side: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("same.csv.truth.json")).unwrap())
            .unwrap();
    let seed = side["seed"].as_u64().unwrap();
    assert!(
        csv.contains(&format!("seed {seed};")),
        "the CSV's header and its sidecar come from different runs (sidecar seed {seed})"
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".part") || n.ends_with(".lock"))
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

#[test]
fn a_folder_in_the_sidecars_place_leaves_no_record_alone() {
    // it wrote r.csv, then failed on r.csv.truth.json ("Is a directory"): a record without
    // its truth file
    let dir = scratch("atomic_side_folder");
    let out = dir.join("r.csv");
    std::fs::create_dir_all(dir.join("r.csv.truth.json")).unwrap();
    for force in [false, true] {
        let mut args = vec!["rig", "cv1", "--t-end", "0.5", "--out", s(&out)];
        if force {
            args.push("--force");
        }
        support::fails_with(
            &args,
            &["r.csv.truth.json` is a folder", "choose another --out"],
        );
        assert!(!out.exists());
    }
}
