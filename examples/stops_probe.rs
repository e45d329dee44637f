//! Probe records for end stops in the measured acceleration: `stops_probe FILE.csv ...`.
use stirling_models::data::read_csv;
use stirling_models::diagnose::stops_equation::probe;

fn main() {
    for path in std::env::args().skip(1) {
        let data = match read_csv(std::path::Path::new(&path)) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{path}: {e}");
                continue;
            }
        };
        let n = data.len();
        let sides = probe(&data, 0, n * 6 / 10).unwrap_or_default();
        let line: Vec<String> = sides
            .iter()
            .map(|s| {
                format!(
                    "{}{} {:.2}mm k/m {:.2e} share {:.3} ({})",
                    s.channel,
                    if s.side > 0 { "+" } else { "-" },
                    s.travel * 1e3,
                    -s.coefficient,
                    s.share,
                    s.beyond
                )
            })
            .collect();
        println!("{path}: {}", line.join(" | "));
    }
}
