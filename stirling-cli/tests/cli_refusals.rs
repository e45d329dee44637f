//! Records that cannot carry a result are refused with the reason and a non-zero exit, never
//! answered: no motion (`fit` and `diagnose`), too few cycles (`fit`), too short to hold
//! out (`diagnose`); and bounds that cannot be used (`fit --bounds`).

mod support;

use support::{fails_with, s, scratch};

fn write(name: &str, rows: usize, moving: bool) -> std::path::PathBuf {
    let dir = scratch(name);
    let f = dir.join(format!("{name}.csv"));
    let mut text = String::from("t,p,x,y\n");
    for k in 0..rows {
        let t = k as f64 * 5e-4;
        let w = if moving {
            (2.0 * std::f64::consts::PI * 13.4 * t).sin()
        } else {
            0.0
        };
        text.push_str(&format!(
            "{t},{},{},{}\n",
            101325.0 + 7000.0 * w,
            0.131 + 0.01 * w,
            0.046 + 0.008 * w
        ));
    }
    std::fs::write(&f, text).unwrap();
    f
}

#[test]
fn a_record_without_motion_is_refused_by_fit_and_diagnose() {
    let f = write("still", 2000, false);
    fails_with(
        &["fit", "cv1", "--data", s(&f)],
        &["does not move enough to fit", "is the engine running"],
    );
    // the diagnosis checks its blocks first: no cycle to hold out
    fails_with(
        &["diagnose", "cv1", "--data", s(&f)],
        &["fewer than two cycles"],
    );
}

#[test]
fn a_record_shorter_than_two_cycles_is_refused_by_fit() {
    // 0.1 s at 2 kHz: about 1.3 cycles of a 13.4 Hz motion
    let f = write("short", 200, true);
    fails_with(&["fit", "cv1", "--data", s(&f)], &["fewer than two cycles"]);
}

#[test]
fn a_record_too_short_to_hold_out_is_refused_by_diagnose() {
    // 0.35 s, the length of the seed's start-up records
    let f = write("seedlike", 700, true);
    fails_with(
        &["diagnose", "cv1", "--data", s(&f)],
        &["too short to diagnose"],
    );
}

#[test]
fn bounds_the_fit_cannot_use_are_refused_by_name() {
    let f = write("bounded", 2000, true);
    let dir = scratch("bounds_files");
    for (name, text, says) in [
        (
            "unknown.toml",
            "kq = [1.0, 2.0]\n",
            "unknown parameter `kq`",
        ),
        ("reversed.toml", "kd = [700.0, 600.0]\n", "lo < hi"),
        ("start.toml", "kd = [700.0, 800.0]\n", "outside [700, 800]"),
    ] {
        let b = dir.join(name);
        std::fs::write(&b, text).unwrap();
        fails_with(&["fit", "cv1", "--data", s(&f), "--bounds", s(&b)], &[says]);
        // the diagnosis's calibration takes the same file
        fails_with(
            &["diagnose", "cv1", "--data", s(&f), "--bounds", s(&b)],
            &[says],
        );
    }
    let missing = dir.join("missing.toml");
    fails_with(
        &["fit", "cv1", "--data", s(&f), "--bounds", s(&missing)],
        &["cannot read", "missing.toml"],
    );
}
