//! `stirling sweep`: each point equals a single `simulate --limit-cycle` run at its
//! parameters; shards merged equal the unsharded run; bad input is refused clearly; a failed
//! point is recorded, never fatal.

mod support;

use serde_json::Value;
use support::{fails_with, s, scratch, stirling, succeeds};

fn json(path: &std::path::Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The points of a sweep.json, without the shard field (merged vs whole).
fn points(v: &Value) -> Vec<Value> {
    v["points"].as_array().unwrap().clone()
}

#[test]
fn sweep_points_equal_single_limit_cycle_runs() {
    let dir = scratch("sweep_single");
    let out = dir.join("sw");
    succeeds(&[
        "sweep",
        "cv1",
        "--grid",
        "Th=650,700",
        "--settle",
        "10",
        "--out",
        s(&out),
    ]);
    let v = json(&out.join("sweep.json"));
    for (k, th) in ["650", "700"].iter().enumerate() {
        let pt = &v["points"][k];
        assert_eq!(pt["outcome"], "runs", "{pt}");
        let set = format!("Th={th}");
        let run = stirling(&[
            "simulate",
            "cv1",
            "--set",
            &set,
            "--t-end",
            "10",
            "--limit-cycle",
            "--json",
        ]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let lc: Value = serde_json::from_slice(&run.stdout).unwrap();
        let get = |v: &Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
        let (f, f_sim) = (get(pt, "frequency_hz"), get(&lc, "frequency_hz"));
        let (x, x_sim) = (get(pt, "x_stroke") / 2.0, get(&lc, "x_amp"));
        let (w, w_sim) = (get(pt, "power_w"), get(&lc, "power_w"));
        assert!((f / f_sim - 1.0).abs() < 1e-6, "frequency {f} vs {f_sim}");
        assert!((x / x_sim - 1.0).abs() < 1e-5, "amplitude {x} vs {x_sim}");
        assert!((w / w_sim - 1.0).abs() < 1e-4, "power {w} vs {w_sim}");
    }
}

#[test]
fn shards_merged_equal_the_whole_sweep() {
    let dir = scratch("sweep_shards");
    let whole = dir.join("whole");
    let grid = ["--grid", "Th=500:700:3", "--grid", "Pmean=0.8e5,1.2e5"];
    let mut args = vec!["sweep", "cv1", "--poles-only", "--out", s(&whole)];
    args.extend(grid);
    succeeds(&args);
    let mut files = Vec::new();
    for i in 1..=3 {
        let part = dir.join(format!("part{i}"));
        let shard = format!("{i}/3");
        let mut a = vec![
            "sweep",
            "cv1",
            "--poles-only",
            "--shard",
            &shard,
            "--out",
            s(&part),
        ];
        a.extend(grid);
        succeeds(&a);
        files.push(part.join("sweep.json"));
    }
    let merged = dir.join("merged");
    let mut m = vec!["sweep-merge"];
    m.extend(files.iter().map(|f| s(f)));
    m.extend(["--out", s(&merged)]);
    succeeds(&m);
    assert_eq!(
        points(&json(&whole.join("sweep.json"))),
        points(&json(&merged.join("sweep.json")))
    );
    // the default tie: Pb moved with Pmean, and the CSV has a row per point
    let csv = std::fs::read_to_string(merged.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 6);
    // a missing shard is refused
    fails_with(
        &[
            "sweep-merge",
            s(&files[0]),
            s(&files[1]),
            "--out",
            s(&dir.join("m2")),
        ],
        &["a shard is missing"],
    );
}

#[test]
fn bad_sweeps_are_refused_and_failed_points_recorded() {
    let dir = scratch("sweep_bad");
    let out = dir.join("o");
    fails_with(
        &["sweep", "cv1", "--grid", "Tx=1,2", "--out", s(&out)],
        &["no parameter `Tx`"],
    );
    fails_with(
        &["sweep", "cv1", "--grid", "Th=1:2", "--out", s(&out)],
        &["--grid `Th=1:2`"],
    );
    fails_with(
        &[
            "sweep",
            "cv1",
            "--grid",
            "Th=600",
            "--shard",
            "4/3",
            "--out",
            s(&out),
        ],
        &["--shard `4/3`"],
    );
    // Th below Tk is unphysical: recorded as failed with its reason, the sweep goes on
    succeeds(&[
        "sweep",
        "cv1",
        "--grid",
        "Th=200,650",
        "--poles-only",
        "--out",
        s(&out),
    ]);
    let v = json(&out.join("sweep.json"));
    assert_eq!(v["points"][0]["outcome"], "failed");
    assert!(v["points"][0]["error"].as_str().unwrap().contains("Th"));
    assert_ne!(v["points"][1]["outcome"], "failed");
    // outputs are not overwritten without --force
    fails_with(
        &[
            "sweep",
            "cv1",
            "--grid",
            "Th=650",
            "--poles-only",
            "--out",
            s(&out),
        ],
        &["--force"],
    );
}
