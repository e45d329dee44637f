//! Errors a user can act on (issue 38, "errors a user cannot act on"): each names its cause
//! and a next step - old Mac line endings, a negative seed, an empty self-check evaluation
//! set, the parameter value where a root locus fails.

mod support;

use support::{fails_with, s, scratch};

#[test]
fn carriage_return_line_ends_are_named_not_an_empty_file() {
    let dir = scratch("msg_cr");
    let f = dir.join("mac.csv");
    let mut text = String::from("t,p,x,y\r");
    for k in 0..100 {
        text.push_str(&format!("{},101325,0.001,0.002\r", k as f64 * 1e-3));
    }
    std::fs::write(&f, text).unwrap();
    let err = fails_with(
        &["fit", "cv1", "--data", s(&f)],
        &[
            "carriage returns (CR)",
            "old Mac line endings",
            "convert them to LF",
        ],
    );
    assert!(!err.contains("empty"), "{err}");
}

#[test]
fn a_negative_seed_is_refused_by_its_range_not_taken_for_an_option() {
    let dir = scratch("msg_seed");
    for args in [
        &["rig", "cv1", "--seed", "-1", "--out", s(&dir.join("r.csv"))][..],
        &["diagnose", "--self-check", "--seed", "-1", "--out", s(&dir)][..],
    ] {
        let err = fails_with(args, &["'-1'", "a seed is a whole number from 0"]);
        assert!(!err.contains("to pass '-1' as a value"), "{err}");
    }
    fails_with(
        &[
            "rig",
            "cv1",
            "--seed",
            "1.5",
            "--out",
            s(&dir.join("r.csv")),
        ],
        &["not a whole number"],
    );
}

#[test]
fn an_empty_self_check_evaluation_set_is_refused_up_front() {
    let dir = scratch("msg_selfcheck");
    let start = std::time::Instant::now();
    fails_with(
        &[
            "diagnose",
            "--self-check",
            "--seeds",
            "1:0",
            "--clean",
            "10:0",
            "--out",
            s(&dir),
        ],
        &["evaluation set is empty", "--seeds 1:1"],
    );
    // it took 44 s of tuning cases before
    assert!(start.elapsed().as_secs_f64() < 10.0);
    assert!(!dir.join("selfcheck.json").exists());
}

#[test]
fn an_unknown_self_check_case_is_refused_with_the_labels_there_are() {
    let dir = scratch("msg_selfcheck_cases");
    let start = std::time::Instant::now();
    fails_with(
        &[
            "diagnose",
            "--self-check",
            "--cases",
            "leak+leak",
            "--out",
            s(&dir),
        ],
        &["no case `leak+leak`", "end_stops+leak", "outside:h_speed"],
    );
    assert!(start.elapsed().as_secs_f64() < 10.0);
    assert!(!dir.join("selfcheck.json").exists());
}

#[test]
fn kept_self_check_records_are_not_overwritten_without_force() {
    let dir = scratch("msg_selfcheck_records");
    let records = dir.join("records");
    std::fs::create_dir_all(&records).unwrap();
    std::fs::write(records.join("case3.csv"), "t,p,x,y\n").unwrap();
    fails_with(
        &[
            "diagnose",
            "--self-check",
            "--keep-records",
            "--out",
            s(&dir),
        ],
        &["--keep-records", "case3.csv", "pass --force to overwrite"],
    );
    assert_eq!(
        std::fs::read_to_string(records.join("case3.csv")).unwrap(),
        "t,p,x,y\n"
    );
}

#[test]
fn a_root_locus_names_the_parameter_value_where_it_fails() {
    fails_with(
        &[
            "locus", "cv1", "--param", "Pb", "--from", "1e5", "--to", "1e7", "--steps", "5",
        ],
        &["at Pb = ", "point ", "sweep a range that ends before it"],
    );
}

#[test]
fn a_record_sampled_once_a_second_is_refused_as_aliased_not_as_a_still_engine() {
    // 13.4 Hz sampled at 1 Hz: the samples trace a 0.4 Hz alias; it was "does `p` move? is
    // the engine running?" (and kd 55.8 instead of 650.7 on the rig's record)
    let f = scratch("msg_alias").join("alias.csv");
    let mut text = String::from("t,p,x,y\n");
    for k in 0..600 {
        let t = k as f64;
        let w = (std::f64::consts::TAU * 13.4 * t).sin();
        let v = (std::f64::consts::TAU * 13.4 * t + 1.4).sin();
        text.push_str(&format!(
            "{t},{},{},{}\n",
            101325.0 + 5800.0 * w,
            0.0079 * v,
            0.0062 * w
        ));
    }
    std::fs::write(&f, text).unwrap();
    for cmd in ["fit", "diagnose"] {
        let err = fails_with(&[cmd, "cv1", "--data", s(&f)], &["the model at", "alias"]);
        assert!(!err.contains("is the engine running"), "{err}");
    }
}

#[test]
fn a_name_given_twice_in_a_list_option_is_refused() {
    let dir = scratch("msg_lists");
    let out = dir.join("r.csv");
    for args in [
        &["rig", "cv1", "--channels", "x,x", "--out", s(&out)][..],
        &[
            "rig",
            "cv1",
            "--effect",
            "leak=1e-8",
            "--effect",
            "leak=2e-8",
            "--out",
            s(&out),
        ][..],
        &[
            "rig",
            "cv1",
            "--noise",
            "x=1e-5",
            "--noise",
            "x=2e-5",
            "--out",
            s(&out),
        ][..],
        &[
            "diagnose",
            "--self-check",
            "--strengths",
            "1,1",
            "--out",
            s(&dir),
        ][..],
    ] {
        fails_with(args, &["is named twice", "name each once"]);
    }
    assert!(!out.exists());
}

#[test]
fn a_record_without_a_channel_the_model_reads_is_named() {
    // columns t,a,b,c: it ended in "the training block holds fewer than two cycles"
    let f = scratch("msg_columns").join("other.csv");
    let mut text = String::from("t,a,b,c\n");
    for k in 0..4000 {
        let t = k as f64 * 5e-4;
        let w = (std::f64::consts::TAU * 13.4 * t).sin();
        text.push_str(&format!(
            "{t},{},{},{}\n",
            101325.0 + 5800.0 * w,
            0.0079 * w,
            0.0062 * w
        ));
    }
    std::fs::write(&f, text).unwrap();
    for cmd in ["fit", "diagnose"] {
        let err = fails_with(
            &[cmd, "cv1", "--data", s(&f)],
            &[
                "none of its columns (a, b, c)",
                "`cv1` reads (p, p_hot, x, y",
                "t,p,x,y",
            ],
        );
        assert!(!err.contains("fewer than two cycles"), "{err}");
    }
}

#[test]
fn a_limit_cycle_of_an_engine_stable_at_rest_is_refused_with_the_cause() {
    // Th = 320 K against Tk = 300 K: every pole at rest is stable. A long run closed the
    // shooting on the rest state and printed a "limit cycle" of zero amplitude with exit 0;
    // a short one said "run longer".
    for t_end in ["2", "0.2"] {
        let err = fails_with(
            &[
                "simulate",
                "cv1",
                "--set",
                "Th=320",
                "--limit-cycle",
                "--t-end",
                t_end,
            ],
            &[
                "no limit cycle",
                "stable at rest",
                "stirling linearize",
                "temperature ratio",
            ],
        );
        assert!(!err.contains("run longer"), "{err}");
    }
}

#[test]
fn sign_flipped_positions_are_named_when_the_fit_fails() {
    // x and y measured in the other direction: it ended in "did not converge ... a longer
    // record may help"
    let flipped = support::edited_rig_record(&scratch("msg_flipped"), "flipped.csv", |f| {
        f.iter()
            .enumerate()
            .map(|(i, v)| match i {
                2 | 3 => format!("{}", -v.parse::<f64>().unwrap()),
                _ => v.to_string(),
            })
            .collect()
    });
    let err = fails_with(
        &["fit", "cv1", "--data", s(&flipped)],
        &[
            "fits no channel even roughly",
            "sign-flipped",
            "a longer record will not help",
        ],
    );
    assert!(!err.contains("may help"), "{err}");
}
