//! End stops seen in the measured acceleration (`diagnose::stops_equation`), outside a
//! diagnosis:
//!
//! - `stops_probe FILE.csv ...`: each side of each body at its best travel, on the first
//!   60 % of each record (the diagnosis's training block);
//! - `stops_probe --self-check [SEEDS_TUNE:SEEDS_EVAL]`: every record of the verdict
//!   self-check (default seeds 1:2, 4:20 clean records), recorded and probed without a
//!   diagnosis; prints the largest share per record and whether its truth has stops.
use stirling_models::data::{read_csv, Measured};
use stirling_models::diagnose::selfcheck::plan::plan;
use stirling_models::diagnose::selfcheck::record::record;
use stirling_models::diagnose::selfcheck::VerdictOptions;
use stirling_models::diagnose::stops_equation::{probe, StopSide, SEEN_SHARE};

fn sides(data: &Measured) -> Vec<StopSide> {
    probe(data, 0, data.len() * 6 / 10).unwrap_or_default()
}

fn line(s: &[StopSide]) -> String {
    s.iter()
        .map(|s| {
            format!(
                "{}{} {:.2} mm, -coef {:.2e}/s^2, share {:.3} ({} beyond)",
                s.channel,
                if s.side > 0 { "+" } else { "-" },
                s.travel * 1e3,
                -s.coefficient,
                s.share,
                s.beyond
            )
        })
        .collect::<Vec<_>>()
        .join(" | ")
}

fn self_check(seeds: (usize, usize)) {
    let opts = VerdictOptions {
        seeds,
        clean: (4, 20),
        ..Default::default()
    };
    let dir = std::env::temp_dir().join(format!("stops-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (mut worst_without, mut least_with) = (0.0f64, f64::INFINITY);
    for case in plan(&opts).expect("the self-check's plan") {
        let label = case.truth.label();
        let Ok(data) = record(&opts, &case, &dir) else {
            println!("{label}: no record");
            continue;
        };
        let most = sides(&data).iter().map(|s| s.share).fold(0.0, f64::max);
        let stops = label.contains("end_stops");
        if stops {
            least_with = least_with.min(most);
        } else {
            worst_without = worst_without.max(most);
        }
        let seen = most > SEEN_SHARE;
        let mark = if seen == stops { "" } else { "  <- WRONG" };
        println!(
            "{:>4} {label:<40} share {most:.4} seen {seen}{mark}",
            case.index
        );
    }
    println!("largest share without stops {worst_without:.4}, least with stops {least_with:.4} (level {SEEN_SHARE})");
    let _ = std::fs::remove_dir_all(&dir);
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--self-check") {
        let seeds = args
            .get(1)
            .and_then(|s| s.split_once(':'))
            .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
            .unwrap_or((1, 2));
        return self_check(seeds);
    }
    for path in args {
        match read_csv(std::path::Path::new(&path)) {
            Ok(d) => println!("{path}: {}", line(&sides(&d))),
            Err(e) => eprintln!("{path}: {e}"),
        }
    }
}
