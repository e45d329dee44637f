//! The figure check: every figure the command line writes (`linearize`, `simulate`, `locus`,
//! `fit --plot`, `diagnose --report`) is rendered on a small fast model, and each SVG is text
//! with axis labels that carry their unit (`[rad/s]`, `(s)`); the files written are the ones
//! the command names on stderr.

mod support;

use std::path::{Path, PathBuf};

use support::{s, scratch, succeeds};

/// The text elements of an SVG as `(attributes, content)`.
fn texts(svg: &str) -> Vec<(String, String)> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| {
            let (attrs, rest) = t.split_once('>')?;
            let (content, _) = rest.split_once("</text>")?;
            Some((attrs.to_string(), content.trim().to_string()))
        })
        .collect()
}

/// Plotters' axis descriptions: rotated (y) or bottom-anchored (x) text.
fn axis_labels(svg: &str) -> (Vec<String>, Vec<String>) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (attrs, content) in texts(svg) {
        if attrs.contains("transform=\"rotate(") {
            y.push(content);
        } else if attrs.contains("dy=\"-0.5ex\"") {
            x.push(content);
        }
    }
    (x, y)
}

/// `label` ends with a unit in brackets or parentheses, e.g. `t [s]`, `phase (deg)`.
fn has_unit(label: &str) -> bool {
    let label = label.replace("&amp;", "&");
    [('[', ']'), ('(', ')')].iter().any(|&(open, close)| {
        label.ends_with(close)
            && label[..label.len() - 1]
                .rfind(open)
                .is_some_and(|i| label.len() - 1 > i + 1)
    })
}

/// Check every SVG in `dir` and that they are exactly the figures named in `stderr`; their
/// number.
fn check_figures(dir: &Path, stderr: &str) -> usize {
    let mut on_disk: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    on_disk.sort();
    let mut reported: Vec<PathBuf> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("wrote "))
        .map(PathBuf::from)
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    reported.sort();
    assert_eq!(on_disk, reported, "figures written vs named:\n{stderr}");
    assert!(!on_disk.is_empty(), "no figure in {}", dir.display());
    for f in &on_disk {
        let bytes = std::fs::read(f).unwrap();
        let svg = String::from_utf8(bytes).unwrap_or_else(|_| panic!("{}: not text", f.display()));
        assert!(
            svg.contains("<svg") && svg.trim_end().ends_with("</svg>"),
            "{}: not a complete SVG",
            f.display()
        );
        let (x, y) = axis_labels(&svg);
        assert!(!x.is_empty(), "{}: no x axis label", f.display());
        assert!(!y.is_empty(), "{}: no y axis label", f.display());
        for l in x.iter().chain(&y) {
            assert!(has_unit(l), "{}: axis label `{l}` has no unit", f.display());
        }
    }
    on_disk.len()
}

/// Run `args` with `--plot DIR` (or `option`) into a fresh folder; the figures checked.
fn figures(name: &str, args: &[&str], option: &str) -> (PathBuf, usize) {
    let dir = scratch(name).join("fig");
    let mut all = args.to_vec();
    all.extend([option, s(&dir)]);
    let err = succeeds(&all);
    let n = check_figures(&dir, &err);
    (dir, n)
}

#[test]
fn unit_detection() {
    assert!(has_unit("t [s]") && has_unit("Frequency w (rad/s)") && has_unit("ratio [-]"));
    assert!(!has_unit("p") && !has_unit("t []") && !has_unit("[s] t"));
}

#[test]
fn linearize_figures() {
    let (dir, n) = figures("fig_lin_schmidt", &["linearize", "schmidt"], "--plot");
    assert_eq!(n, 2);
    let bode = std::fs::read_to_string(dir.join("bode.svg")).unwrap();
    let t: Vec<String> = texts(&bode).into_iter().map(|t| t.1).collect();
    // the broken loop in the title, the dominant decades 10^0..10^3, powers of ten as ticks
    assert!(t
        .iter()
        .any(|t| t.starts_with("Broken loop") && t.contains("pressure")));
    for tick in ["10⁰", "10¹", "10²", "10³"] {
        assert!(t.iter().any(|t| t == tick), "tick {tick} missing: {t:?}");
    }
    assert!(
        !t.iter().any(|t| t == "10⁴" || t == "10⁻¹" || t == "1000.0"),
        "{t:?}"
    );
    assert!(t.iter().any(|t| t.starts_with("Gm = -6.63 dB at 81.6")));
    assert!(t.iter().any(|t| t.starts_with("Pm = -79.50 deg at 91.3")));
    let (_, n) = figures(
        "fig_lin_ns1",
        &["linearize", "nsection", "--n", "1"],
        "--plot",
    );
    assert_eq!(n, 2);
}

#[test]
fn simulate_figures() {
    let (_, n) = figures(
        "fig_sim_cv1",
        &["simulate", "cv1", "--t-end", "0.3"],
        "--plot",
    );
    assert_eq!(n, 1, "startup.svg");
    let (dir, n) = figures(
        "fig_sim_lc",
        &[
            "simulate",
            "nsection",
            "--n",
            "1",
            "--t-end",
            "4",
            "--limit-cycle",
        ],
        "--plot",
    );
    assert_eq!(n, 2, "startup.svg and pv.svg");
    assert!(dir.join("pv.svg").is_file());
}

#[test]
fn locus_figure() {
    let (dir, n) = figures(
        "fig_locus",
        &[
            "locus", "schmidt", "--param", "Th", "--from", "320", "--to", "900", "--steps", "11",
        ],
        "--plot",
    );
    assert_eq!(n, 1);
    let svg = std::fs::read_to_string(dir.join("locus.svg")).unwrap();
    let (_, y) = axis_labels(&svg);
    assert!(y.iter().any(|l| l == "Th [K]"), "colour bar label: {y:?}");
    assert!(
        svg.contains("RHP count changes between"),
        "stability crossing named"
    );
}

#[test]
fn fit_and_diagnose_figures() {
    let dir = scratch("fig_fit_data");
    let data = dir.join("data.csv");
    succeeds(&[
        "rig",
        "cv1",
        "--settle",
        "3",
        "--t-end",
        "1",
        "--out",
        s(&data),
    ]);
    let (_, n) = figures("fig_fit", &["fit", "cv1", "--data", s(&data)], "--plot");
    assert!(n >= 3, "stage and free-run figures: {n}");
    let (dir, n) = figures(
        "fig_diagnose",
        &["diagnose", "cv1", "--data", s(&data), "--effects", "leak"],
        "--report",
    );
    assert!(n >= 3, "residual and overlay figures: {n}");
    assert!(dir.join("report.md").is_file());
}
