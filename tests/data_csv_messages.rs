//! Messages of the CSV reader that once misled: a byte-order mark, a gap in the sampling, a
//! value out of range (its row, a short number), a file in another format.

use stirling::models::data::{check_uniform, parse_csv, parse_csv_bytes, read_csv, read_csv_lines};

fn err(text: &str) -> String {
    let e = parse_csv("rec.csv", text).unwrap_err().to_string();
    eprintln!("{e}");
    e
}

fn rows(n: usize, dt: f64) -> Vec<(f64, String)> {
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            (
                t,
                format!(
                    "{},{}",
                    1e6 + 1e3 * (k as f64).sin(),
                    1e-3 * (k as f64).cos()
                ),
            )
        })
        .collect()
}

#[test]
fn byte_order_mark_is_ignored() {
    let m = parse_csv("rec.csv", "\u{feff}t,p\n0,101325\n0.001,101330\n").unwrap();
    assert_eq!(m.len(), 2);
    let bytes = b"\xef\xbb\xbft,x\n0,0.001\n0.001,0.002\n";
    assert_eq!(parse_csv_bytes("rec.csv", bytes).unwrap().len(), 2);
}

#[test]
fn a_gap_is_reported_where_it_is() {
    // 1 ms sampling, ten samples missing after t = 0.040 s
    let mut text = String::from("# comment\nt,p,x\n");
    for (t, r) in rows(100, 1e-3)
        .into_iter()
        .filter(|(t, _)| !(0.0405..0.0505).contains(t))
    {
        text.push_str(&format!("{t},{r}\n"));
    }
    let m = parse_csv("rec.csv", &text).unwrap();
    let e = check_uniform(&m, None).unwrap_err();
    assert_eq!(e.row, 42, "the 42nd sample ends the gap: {e}");
    let s = e.to_string();
    assert!(
        s.contains("a gap of 0.011 s from t = 0.04 s (row 41) to t = 0.051 s"),
        "{s}"
    );
    assert!(s.contains("typical interval is 0.001 s"), "{s}");
    // with the file lines: two lines before the first sample
    let dir = std::env::temp_dir().join(format!("stirling_csv_gap_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("gap.csv");
    std::fs::write(&f, &text).unwrap();
    let (m, lines) = read_csv_lines(&f).unwrap();
    let e = check_uniform(&m, Some(&lines)).unwrap_err();
    assert_eq!(e.row, 44, "{e}");
    assert!(e.to_string().contains("(row 43)"), "{e}");
    // a short step is found as well
    let text = "t,x\n0,0\n0.001,0\n0.002,0\n0.0025,0\n0.0035,0\n0.0045,0\n";
    let e = check_uniform(&parse_csv("r.csv", text).unwrap(), None).unwrap_err();
    assert_eq!(e.row, 4, "{e}");
    assert!(e.to_string().contains("a short step"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn out_of_range_values_at_their_row_with_short_numbers() {
    let mut text = String::from("t,p,x\n");
    for (t, r) in rows(20, 1e-3) {
        text.push_str(&format!("{t},{r}\n"));
    }
    let with = |line: usize, row: &str| {
        let mut v: Vec<String> = text.lines().map(String::from).collect();
        v[line - 1] = row.to_string();
        v.join("\n")
    };
    let big = format!("1{}", "0".repeat(299));
    let s = err(&with(9, &format!("0.007,1e6,{big}")));
    assert!(
        s.starts_with("rec.csv: row 9, column `x`: position 1.000000e299 m is out of range"),
        "{s}"
    );
    assert!(s.len() < 200, "{s}");
    let s = err(&with(12, "0.010,-5,0.001"));
    assert!(
        s.starts_with("rec.csv: row 12, column `p`: pressure -5 Pa: pressure must be absolute"),
        "{s}"
    );
    let s = err(&with(5, "0.003,1e6,1e400"));
    assert!(
        s.starts_with("rec.csv: row 5, column `x`: `1e400` is out of the range of a 64-bit number"),
        "{s}"
    );
    let huge = format!("1{}", "0".repeat(320));
    let s = err(&with(6, &format!("0.004,{huge},0.001")));
    assert!(s.starts_with("rec.csv: row 6, column `p`: `100000000000000000000000...` (321 characters) is out of the range"), "{s}");
    let s = err(&with(7, &format!("0.005,1e6,{}x", "9".repeat(100))));
    assert!(
        s.contains("not a number: `999999999999999999999999...` (101 characters)"),
        "{s}"
    );
}

#[test]
fn the_assumed_format_is_named() {
    let json = "{\"t\": [0, 0.001], \"p\": [101325, 101325]}\n";
    let s = parse_csv("rec.json", json).unwrap_err().to_string();
    assert!(s.contains("missing column `t`"), "{s}");
    assert!(
        s.contains("read as CSV") && s.contains("`.json`") && s.contains("looks like JSON"),
        "{s}"
    );
    let s = parse_csv("rec.toml", "t = [0, 1]\np = [1, 2]\n")
        .unwrap_err()
        .to_string();
    assert!(
        s.contains("`.toml`") && s.contains("looks like TOML"),
        "{s}"
    );
    let s = parse_csv("rec.csv", "t;p\n0;101325\n")
        .unwrap_err()
        .to_string();
    assert!(
        s.contains("read as CSV") && s.contains("`;` separators"),
        "{s}"
    );
    assert!(!s.contains("extension"), "{s}");
    let s = parse_csv_bytes("rec.csv", b"t,p\n0,\xff\xfe\n")
        .unwrap_err()
        .to_string();
    assert!(
        s.starts_with("rec.csv: row 2, column ``: not a text file: invalid UTF-8 at byte 6"),
        "{s}"
    );
}

#[test]
fn files_are_read_as_bytes() {
    let dir = std::env::temp_dir().join(format!("stirling_csv_bytes_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bom.csv");
    std::fs::write(&f, "\u{feff}t,p\r\n0,101325\r\n0.001,101330\r\n").unwrap();
    assert_eq!(read_csv(&f).unwrap().len(), 2);
    std::fs::remove_dir_all(&dir).ok();
}
