//! `--data` read by `fit` and `diagnose`: a gap in the sampling is refused at its file line,
//! a file in another format says the format assumed.

mod support;

use support::{fails_with, s, scratch};

#[test]
fn a_gap_is_refused_at_its_line() {
    let dir = scratch("data_gap");
    let f = dir.join("gap.csv");
    let mut text = String::from("# rig record\nt,p,x,y\n");
    for k in (0..400).filter(|k| !(100..110).contains(k)) {
        let t = k as f64 * 5e-4;
        text.push_str(&format!(
            "{t},{},{},{}\n",
            1e6 + (k as f64).sin(),
            1e-3,
            2e-3
        ));
    }
    std::fs::write(&f, text).unwrap();
    let row = format!(
        "{}: row 103, column `t`: irregular sampling: a gap of 0.0055 s",
        f.display()
    );
    for cmd in ["fit", "diagnose"] {
        fails_with(
            &[cmd, "cv1", "--data", s(&f)],
            &[&row, "t = 0.0495 s (row 102)"],
        );
    }
}

#[test]
fn a_json_file_is_named_as_read_as_csv() {
    let dir = scratch("data_json");
    let f = dir.join("rec.json");
    std::fs::write(&f, "{\"t\": [0, 1]}\n").unwrap();
    fails_with(
        &["fit", "cv1", "--data", s(&f)],
        &["missing column `t`", "read as CSV", "looks like JSON"],
    );
}

#[test]
fn a_unit_the_reader_does_not_know_is_refused_at_the_header() {
    let dir = scratch("data_units");
    let f = dir.join("lab.csv");
    std::fs::write(
        &f,
        "t [ms],p [kPa gauge],x [inch],y [mm]\n0,1.5,0.1,2\n1,1.6,0.1,2\n",
    )
    .unwrap();
    let at = format!("{}: row 1, column `x [inch]`", f.display());
    for cmd in ["fit", "diagnose"] {
        fails_with(
            &[cmd, "cv1", "--data", s(&f)],
            &[&at, "unknown unit `inch`", "mm"],
        );
    }
}
