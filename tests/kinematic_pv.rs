//! The worked example of docs/custom-topologies.md section 13 (`examples/kinematic_pv.rs`): a
//! short record of the gamma LTD written as a lab would, read back, fitted, and its p-V loop
//! drawn. The figures are written, a second run without `--force` is refused before it
//! overwrites them, and the loop areas of record and model agree with the truth's (the rig's
//! run without noise).

#[path = "../examples/kinematic_pv.rs"]
#[allow(dead_code)]
mod example;

#[test]
fn the_worked_example_draws_its_figures_and_the_loops_agree() {
    let dir = std::env::temp_dir().join(format!("kinematic_pv_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let args = example::parse_args(
        ["--out", dir.to_str().unwrap(), "--seconds", "4"]
            .iter()
            .map(|s| s.to_string()),
    )
    .expect("the arguments parse");
    let s = example::run(&args).expect("the example runs");
    for f in &s.files {
        let svg = std::fs::read_to_string(f).expect("the figure is written");
        assert!(
            svg.contains("<svg") && svg.contains("</svg>"),
            "{}",
            f.display()
        );
    }
    let loop_svg = std::fs::read_to_string(&s.files[0]).unwrap();
    for label in ["cm^3", "kPa gauge", "record: W =", "fitted model: W ="] {
        assert!(loop_svg.contains(label), "pv_loop.svg lacks `{label}`");
    }
    let diff_svg = std::fs::read_to_string(&s.files[1]).unwrap();
    for label in ["crank angle [deg]", "noise level"] {
        assert!(
            diff_svg.contains(label),
            "pv_difference.svg lacks `{label}`"
        );
    }
    eprintln!(
        "truth {:.4e} J, record {:.4e} J, model {:.4e} J over {} revolutions; rms {:.2} Pa, noise {:.2} Pa",
        s.work_truth, s.work_record, s.work_model, s.revolutions, s.rms_difference, s.noise
    );
    assert!(s.revolutions >= 2, "{}", s.revolutions);
    // positive work (the loop runs clockwise); record and model within 1 % of the truth's
    // (the rig's run without noise: the noise's share is about 0.2 % on 3 revolutions)
    assert!(s.work_record > 0.0 && s.work_model > 0.0);
    for w in [s.work_record, s.work_model] {
        assert!(
            (w / s.work_truth - 1.0).abs() < 0.01,
            "{w} against {}",
            s.work_truth
        );
    }
    // the difference is the noise: its rms within 30 % of the record's noise level
    assert!((s.rms_difference / s.noise - 1.0).abs() < 0.3);

    // no overwrite without --force, and nothing is changed by the refusal
    let before = std::fs::read(&s.files[0]).unwrap();
    let e = example::run(&args).err().expect("refused").to_string();
    assert!(e.contains("exists: pass --force"), "{e}");
    assert_eq!(std::fs::read(&s.files[0]).unwrap(), before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_arguments_are_refused_with_the_usage() {
    let parse = |v: &[&str]| example::parse_args(v.iter().map(|s| s.to_string()));
    for (args, says) in [
        (&["--seconds", "1"][..], "from 2 to 120"),
        (&["--out", "d", "--seconds", "nan"][..], "`nan`"),
        (&["--out"][..], "needs a value"),
        (&["--bogus"][..], "unknown argument"),
        (&[][..], "--out DIR is required"),
    ] {
        let e = parse(args).expect_err("refused");
        assert!(e.contains(says) && e.contains("usage"), "{args:?}: {e}");
    }
}
