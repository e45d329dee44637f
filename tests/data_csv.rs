//! Measured-data input: every malformed case gives an error naming file, row and column.

use stirling::models::data::{
    cycle_mean, parse_csv, read_csv, remove_position_offsets, write_csv, Measured,
};

fn err(text: &str) -> String {
    let e = parse_csv("rec.csv", text).unwrap_err();
    let s = e.to_string();
    eprintln!("{s}");
    s
}

fn good_rows(n: usize) -> String {
    (0..n)
        .map(|k| {
            format!(
                "{},{},{},{}\n",
                k as f64 * 5e-4,
                101325.0 + 100.0 * k as f64,
                1e-3 * (k as f64 * 0.3).sin(),
                2e-3 * (k as f64 * 0.3).cos()
            )
        })
        .collect()
}

#[test]
fn reads_a_good_file_with_comments_and_extra_columns() {
    let text = format!(
        "# rig output\n\nt,p,x,y,temperature\n{}",
        good_rows(10)
            .lines()
            .map(|l| format!("{l},300\n"))
            .collect::<String>()
    );
    let m = parse_csv("rec.csv", &text).unwrap();
    assert_eq!(m.len(), 10);
    // another column is kept by name (a sensor a model may declare)
    assert_eq!(m.channels(), vec!["p", "x", "y", "temperature"]);
    assert_eq!(m.channel("temperature").unwrap(), &[300.0; 10]);
    assert!(m.p_hot.is_none());
    assert!((m.dt() - 5e-4).abs() < 1e-15);
}

/// A column besides the seed's four that does not hold a number in every row is set aside
/// with its first bad cell (the record still reads; a fit that needs it says where);
/// a seed channel's bad cell is an error at once.
#[test]
fn another_column_with_a_bad_cell_is_set_aside_with_where() {
    let rows: String = good_rows(6)
        .lines()
        .enumerate()
        .map(|(k, l)| format!("{l},{}\n", if k == 3 { "n/a" } else { "1.5e5" }))
        .collect();
    let m = parse_csv("rec.csv", &format!("t,p,x,y,p_bounce\n{rows}")).unwrap();
    assert_eq!(m.channels(), vec!["p", "x", "y"]);
    let e = m.unread("p_bounce").expect("set aside");
    assert_eq!((e.row, e.column.as_str()), (5, "p_bounce"));
    assert!(e.message.contains("n/a"), "{e}");
    // only other columns, all unreadable: the first bad cell is the error
    let only: String = (0..4)
        .map(|k| format!("{},oops\n", k as f64 * 1e-3))
        .collect();
    let s = err(&format!("t,p_bounce\n{only}"));
    assert!(s.contains("row 2") && s.contains("p_bounce"), "{s}");
}

#[test]
fn empty_file() {
    assert_eq!(err(""), "rec.csv: row 1, column `t`: the file is empty: expected a header line with `t` and at least one of p, p_hot, x, y");
    assert!(err("# only a comment\n").contains("the file is empty"));
}

#[test]
fn missing_time_column() {
    assert_eq!(
        err("time,p\n0,101325\n"),
        "rec.csv: row 1, column `t`: missing column `t` (time in s); the header has: time, p"
    );
}

#[test]
fn missing_channels() {
    let s = err("# c\nt\n0\n");
    assert_eq!(s, "rec.csv: row 2, column `p`: no measured channel: expected at least one of the columns p, p_hot, x, y (or a sensor a model declares); the header has: t");
}

#[test]
fn no_data_rows() {
    assert_eq!(
        err("t,p\n"),
        "rec.csv: row 2, column `t`: no data rows after the header"
    );
}

#[test]
fn duplicate_time() {
    let s = err("t,p\n0,101325\n0.001,101325\n0.001,101330\n");
    assert_eq!(s, "rec.csv: row 4, column `t`: duplicate time 0.001 (same as the previous row): time must increase strictly");
}

#[test]
fn time_going_backwards() {
    let s = err("t,p\n0,101325\n0.002,101325\n0.001,101330\n");
    assert_eq!(s, "rec.csv: row 4, column `t`: time goes backwards (0.001 after 0.002): time must increase strictly");
}

#[test]
fn nan_and_infinite_values() {
    assert_eq!(
        err("t,p\n0,101325\n0.001,NaN\n"),
        "rec.csv: row 3, column `p`: NaN or infinite value `NaN`: expected a finite number"
    );
    assert_eq!(
        err("t,x\n0,0.001\n0.001,inf\n"),
        "rec.csv: row 3, column `x`: NaN or infinite value `inf`: expected a finite number"
    );
}

#[test]
fn text_in_numbers() {
    assert_eq!(
        err("t,p,x\n0,101325,0.001\n0.001,101kPa,0.001\n"),
        "rec.csv: row 3, column `p`: not a number: `101kPa`"
    );
    assert_eq!(
        err("t,p\n0,101325\n0.001,\n"),
        "rec.csv: row 3, column `p`: empty value: expected a number"
    );
}

#[test]
fn short_row() {
    assert_eq!(
        err("t,p,x\n0,101325,0.001\n0.001,101325\n"),
        "rec.csv: row 3, column `x`: the row has 2 fields, the header 3: value of `x` missing"
    );
}

#[test]
fn pressure_in_kpa_or_bar() {
    let kpa = "t,p\n0,101.3\n0.001,101.5\n0.002,101.1\n";
    assert_eq!(err(kpa), "rec.csv: row 2, column `p`: pressure looks like kPa (median 101.3000): expected absolute pressure in Pa, e.g. 101325, or the unit named in the header, e.g. `p [kPa]` (rows 2-4)");
    let bar = "t,p_hot\n0,1.013\n0.001,1.015\n";
    assert_eq!(err(bar), "rec.csv: row 2, column `p_hot`: pressure looks like bar or MPa (median 1.0150): expected absolute pressure in Pa, e.g. 101325, or the unit named in the header, e.g. `p_hot [bar]` (rows 2-3)");
    assert!(err("t,p\n0,-200\n0.001,300\n0.002,-100\n").contains("pressure must be absolute"));
}

#[test]
fn positions_in_mm() {
    let s = err("t,x,y\n0,5.0,0.001\n0.001,-4.0,0.001\n");
    assert_eq!(s, "rec.csv: row 2, column `x`: position looks like mm (largest magnitude 5.0000): expected metres, e.g. 0.005 for 5 mm, or the unit named in the header, e.g. `x [mm]` (rows 2-3)");
}

#[test]
fn duplicate_column() {
    assert_eq!(
        err("t,p,p\n0,1,1\n"),
        "rec.csv: row 1, column `p`: column `p` appears twice in the header"
    );
}

#[test]
fn file_errors_name_the_file() {
    let dir = std::env::temp_dir().join(format!("stirling_data_csv_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.csv");
    std::fs::write(&f, "t,p\n0,101325\n0,101325\n").unwrap();
    let e = read_csv(&f).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "{}: row 3, column `t`: duplicate time",
            f.display()
        )),
        "{e}"
    );
    let e = read_csv(&dir.join("missing.csv")).unwrap_err().to_string();
    assert!(e.contains("cannot read the file"), "{e}");
}

#[test]
fn write_read_roundtrip_and_offsets_are_estimated() {
    let n = 2001;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 5e-4).collect();
    let w = 85.0;
    let x: Vec<f64> = t.iter().map(|t| 0.004 * (w * t).sin() + 0.0012).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| 0.006 * (w * t + 1.0).sin() - 0.0007)
        .collect();
    let m = Measured {
        source: "mem".into(),
        t,
        p: Some(vec![101325.0; n]),
        p_hot: None,
        x: Some(x),
        y: Some(y),
        ..Default::default()
    };
    let dir = std::env::temp_dir().join(format!("stirling_data_rt_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("rt.csv");
    let mut m = m;
    m.others.push(("p_bounce".into(), vec![1.2e5; n]));
    write_csv(&f, &m, &["a comment".into()]).unwrap();
    let mut r = read_csv(&f).unwrap();
    assert_eq!(r.len(), n);
    assert_eq!(r.channels(), vec!["p", "x", "y", "p_bounce"]);
    assert_eq!(r.channel("p_bounce"), m.channel("p_bounce"));
    assert_eq!(r.slice(0.0, 1e-3).channel("p_bounce").unwrap().len(), 3);
    assert!((r.x.as_ref().unwrap()[10] - m.x.as_ref().unwrap()[10]).abs() < 1e-12);
    assert!((cycle_mean(m.x.as_ref().unwrap()) - 0.0012).abs() < 2e-5);
    let off = remove_position_offsets(&mut r);
    eprintln!("estimated offsets {off:?}");
    assert!((off.x - 0.0012).abs() < 2e-5 && (off.y + 0.0007).abs() < 2e-5);
}
