//! Units named in a record's header: a lab record logged in ms, kPa gauge and mm (and a
//! kinematic engine's volume change in cm^3 and crank angle in degrees) reads as the same
//! record in SI units; a unit that is unknown or does not fit its column is refused at the
//! header with what would do.

use stirling::models::data::{parse_csv, units::AMBIENT, Measured};

/// `n` rows of a record in SI units: t (s), p (Pa absolute), x, y (m).
fn si_rows(n: usize) -> Vec<[f64; 4]> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 5e-4;
            [
                t,
                101_325.0 + 3_000.0 * (80.0 * t).sin(),
                4e-3 * (80.0 * t).sin(),
                6e-3 * (80.0 * t + 1.2).sin(),
            ]
        })
        .collect()
}

fn csv(header: &str, rows: &[[f64; 4]], scale: [f64; 4], offset: [f64; 4]) -> String {
    let mut s = format!("{header}\n");
    for r in rows {
        let v: Vec<String> = (0..4)
            .map(|i| format!("{:.15e}", (r[i] - offset[i]) / scale[i]))
            .collect();
        s.push_str(&v.join(","));
        s.push('\n');
    }
    s
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= 1e-12 * y.abs().max(1e-3))
}

fn same(a: &Measured, b: &Measured) {
    assert!(close(&a.t, &b.t), "t differs");
    for c in ["p", "x", "y"] {
        assert!(
            close(a.channel(c).unwrap(), b.channel(c).unwrap()),
            "{c} differs"
        );
    }
}

#[test]
fn a_lab_record_in_ms_kpa_gauge_and_mm_reads_as_the_si_record() {
    let rows = si_rows(400);
    let si = parse_csv("si.csv", &csv("t,p,x,y", &rows, [1.0; 4], [0.0; 4])).unwrap();
    let lab = csv(
        "t [ms],p [kPa gauge],x [mm],y (mm)",
        &rows,
        [1e-3, 1e3, 1e-3, 1e-3],
        [0.0, AMBIENT, 0.0, 0.0],
    );
    same(&parse_csv("lab.csv", &lab).unwrap(), &si);
    let bar = csv(
        "t [s],p [bar],x [cm],y [m]",
        &rows,
        [1.0, 1e5, 1e-2, 1.0],
        [0.0; 4],
    );
    same(&parse_csv("bar.csv", &bar).unwrap(), &si);
    let psig = csv(
        "t,p [psig],x [um],y [mm]",
        &rows,
        [1.0, 6_894.757_293_168, 1e-6, 1e-3],
        [0.0, AMBIENT, 0.0, 0.0],
    );
    same(&parse_csv("psig.csv", &psig).unwrap(), &si);
}

#[test]
fn a_kinematic_record_keeps_its_volume_and_angle_in_si() {
    let text =
        "t [ms],p [kPa gauge],dV [cm^3],theta [deg]\n0,1.5,-2.0,0\n10,1.7,0.5,36\n20,1.2,2.0,72\n";
    let m = parse_csv("ltd.csv", text).unwrap();
    assert!(close(&m.t, &[0.0, 0.01, 0.02]));
    assert!(close(
        m.p.as_deref().unwrap(),
        &[AMBIENT + 1500.0, AMBIENT + 1700.0, AMBIENT + 1200.0]
    ));
    assert!(close(m.channel("dV").unwrap(), &[-2e-6, 0.5e-6, 2e-6]));
    let pi = std::f64::consts::PI;
    assert!(close(
        m.channel("theta").unwrap(),
        &[0.0, pi / 5.0, 2.0 * pi / 5.0]
    ));
}

#[test]
fn a_bad_unit_is_refused_at_the_header_with_what_would_do() {
    let err = |text: &str| parse_csv("rec.csv", text).unwrap_err().to_string();
    let rows = "0,101,1,2\n0.001,102,1,2\n";
    let e = err(&format!("t,p [kPaa],x,y\n{rows}"));
    assert!(
        e.contains("row 1")
            && e.contains("`p [kPaa]`")
            && e.contains("unknown unit `kPaa`")
            && e.contains("kPa"),
        "{e}"
    );
    let e = err(&format!("t,p,x [kPa],y\n{rows}"));
    assert!(e.contains("`x` is a length") && e.contains("mm"), "{e}");
    let e = err(&format!("t [mm],p,x,y\n{rows}"));
    assert!(e.contains("`t` is a time") && e.contains("ms"), "{e}");
    let e = err(&format!("t,p,x [mm gauge],y\n{rows}"));
    assert!(e.contains("only a pressure can be gauge"), "{e}");
}

#[test]
fn a_record_in_kpa_without_a_unit_is_told_how_to_name_it() {
    let text = "t,p,x,y\n0,101.3,0.001,0.002\n0.001,101.4,0.001,0.002\n0.002,101.2,0.001,0.002\n";
    let e = parse_csv("rec.csv", text).unwrap_err().to_string();
    assert!(
        e.contains("looks like kPa") && e.contains("`p [kPa]`"),
        "{e}"
    );
    let text = "t,p,x,y\n0,-0.3,0.001,0.002\n0.001,0.2,0.001,0.002\n0.002,-1.2,0.001,0.002\n";
    let e = parse_csv("rec.csv", text).unwrap_err().to_string();
    assert!(e.contains("`p [kPa gauge]`"), "{e}");
}
