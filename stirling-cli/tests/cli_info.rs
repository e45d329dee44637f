//! `stirling info` end to end: the listing, LaTeX, JSON, the DOT graph (stdout and `--out`
//! with its overwrite guard), and the errors a user meets.

use std::path::PathBuf;
use std::process::{Command, Output};

fn stirling(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stirling"))
        .args(args)
        .output()
        .expect("run stirling")
}

fn ok(args: &[&str]) -> String {
    let out = stirling(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn fails(args: &[&str]) -> String {
    let out = stirling(args);
    assert!(!out.status.success(), "{args:?} should fail");
    String::from_utf8(out.stderr).unwrap()
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cli_info");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let _ = std::fs::remove_file(&path);
    path
}

#[test]
fn listing_shows_states_parameters_and_equations() {
    let s = ok(&["info", "cv2"]);
    assert!(s.starts_with("model cv2, closure full: 8 states"), "{s}");
    for needle in [
        "P_hot",
        "Pa",
        "gas mass in CV cold",
        "Rf",
        "Pa s/kg",
        "regenerator flow resistance",
        "where",
        "P_cold' =",
        "sensors (CSV columns a record may hold)",
        "p_hot   P_hot   Pa",
    ] {
        assert!(s.contains(needle), "missing `{needle}` in\n{s}");
    }
    let frozen = ok(&["info", "cv2", "--closure", "frozen"]);
    assert!(
        frozen.starts_with("model cv2, closure frozen: 6 states"),
        "{frozen}"
    );
    assert!(!frozen.contains("m_hot'"), "{frozen}");
}

#[test]
fn sections_and_aliases() {
    assert!(ok(&["info", "nsection", "--n", "3"])
        .starts_with("model nsection, n = 3, closure full: 14 states"));
    assert!(ok(&["info", "order8", "--closure", "frozen"])
        .starts_with("model nsection, n = 2, closure frozen: 8 states"));
    assert!(ok(&["info", "order4"]).starts_with("model schmidt, closure full: 4 states"));
}

#[test]
fn overridden_parameters_show_their_value_and_default() {
    let s = ok(&["info", "cv1", "--set", "Th=650"]);
    let line = s
        .lines()
        .find(|l| l.trim_start().starts_with("Th "))
        .unwrap();
    assert!(
        line.contains("650") && line.contains("(default 600)"),
        "{line}"
    );
}

#[test]
fn parameter_file_is_read() {
    let path = scratch("engine.toml");
    std::fs::write(&path, "Tk = 320.0\n").unwrap();
    let s = ok(&["info", "cv1", "--params", path.to_str().unwrap()]);
    let line = s
        .lines()
        .find(|l| l.trim_start().starts_with("Tk "))
        .unwrap();
    assert!(
        line.contains("320") && line.contains("(default 300)"),
        "{line}"
    );
}

#[test]
fn latex_equations() {
    let s = ok(&["info", "cv2", "--latex"]);
    assert!(
        s.contains("\\begin{aligned}") && s.contains("\\end{aligned}"),
        "{s}"
    );
    assert!(s.contains("\\dot{"), "{s}");
}

#[test]
fn json_listing() {
    let s = ok(&[
        "info",
        "nsection",
        "--n",
        "2",
        "--closure",
        "frozen",
        "--json",
        "--set",
        "Rf=2e5",
    ]);
    let v: serde_json::Value = serde_json::from_str(&s).unwrap();
    assert_eq!(v["model"], "nsection");
    assert_eq!(v["n"], 2);
    assert_eq!(v["closure"], "frozen");
    assert_eq!(v["n_states"], 8);
    assert_eq!(v["states"].as_array().unwrap().len(), 8);
    assert_eq!(v["states"][4]["unit"], "Pa");
    let sensors = v["sensors"].as_array().unwrap();
    let names: Vec<&str> = sensors
        .iter()
        .map(|s| s["column"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["x", "y", "p", "p_hot"]);
    assert_eq!(sensors[2]["state"], "P_cold");
    assert_eq!(sensors[2]["present"], true);
    let rf = v["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "Rf")
        .unwrap();
    assert_eq!(rf["value"], 2e5);
    assert_eq!(rf["default"], 1e5);
    assert_eq!(rf["unit"], "Pa s/kg");
    assert!(v["equations"].as_str().unwrap().contains("P_hot' ="));
}

#[test]
fn graph_to_stdout() {
    let s = ok(&["info", "cv2", "--graph"]);
    assert!(
        s.starts_with("digraph \"cv2\" {") && s.trim_end().ends_with('}'),
        "{s}"
    );
    for needle in [
        "I: md",
        "C: kd",
        "C: hot",
        "TF: -A",
        "R: Rf",
        "Se: Th",
        "arrowtail=tee",
    ] {
        assert!(s.contains(needle), "missing `{needle}`");
    }
}

#[test]
fn graph_svg_is_drawn_without_graphviz_and_not_overwritten_without_force() {
    let path = scratch("cv1.svg");
    let p = path.to_str().unwrap();
    let _ = std::fs::remove_file(&path);
    let out = ok(&["info", "cv1", "--graph", "--svg", p]);
    assert!(
        !out.contains("digraph"),
        "the DOT went to stdout with --svg: {out}"
    );
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for needle in [
        ">1</text>",
        ">0</text>",
        ">I: md</text>",
        ">TF: -Ar</text>",
        "class=\"stroke\"",
    ] {
        assert!(svg.contains(needle), "missing `{needle}`");
    }
    std::fs::write(&path, "keep me").unwrap();
    let err = fails(&["info", "cv1", "--graph", "--svg", p]);
    assert!(err.contains("exists") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me");
    ok(&["info", "cv1", "--graph", "--svg", p, "--force"]);
}

#[test]
fn graph_to_file_refuses_to_overwrite_without_force() {
    let path = scratch("cv2.dot");
    let p = path.to_str().unwrap();
    ok(&["info", "cv2", "--graph", "--out", p]);
    let first = std::fs::read_to_string(&path).unwrap();
    assert!(first.starts_with("digraph"));
    std::fs::write(&path, "keep me").unwrap();
    let err = fails(&["info", "cv1", "--graph", "--out", p]);
    assert!(err.contains("exists") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep me");
    ok(&["info", "cv1", "--graph", "--out", p, "--force"]);
    assert!(std::fs::read_to_string(&path)
        .unwrap()
        .starts_with("digraph \"cv1\""));
}

#[test]
fn clear_errors() {
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["info", "cv3"],
            &["unknown model `cv3`", "schmidt, cv1, cv2, nsection"],
        ),
        (
            &["info", "nsection", "--n", "0"],
            &["'--n <N>': must be at least 1"],
        ),
        (
            &["info", "cv2", "--n", "3"],
            &["no regenerator sections", "omit --n"],
        ),
        (
            &["info", "schmidt", "--n", "2"],
            &["no regenerator sections"],
        ),
        (&["info", "order7", "--n", "2"], &["fixes n = 1"]),
        (
            &["info", "cv2", "--set", "Thot=700"],
            &["unknown parameter `Thot`", "valid parameters", "Th, Tk"],
        ),
        (&["info", "cv2", "--set", "Th"], &["expected name=value"]),
        (&["info", "cv2", "--set", "Ar=0.01"], &["Ar", "thinner"]),
        (&["info", "cv2", "--closure", "half"], &["full", "frozen"]),
        (
            &["info", "cv2", "--params", "/nonexistent/p.toml"],
            &["cannot read parameter file"],
        ),
        (&["info", "cv2", "--out", "x.dot"], &["--graph"]),
    ];
    for (args, needles) in cases {
        let err = fails(args);
        for n in *needles {
            assert!(err.contains(n), "{args:?}: `{n}` not in\n{err}");
        }
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
