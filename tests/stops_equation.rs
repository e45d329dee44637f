//! End stops seen in the measured acceleration (`diagnose::stops_equation`): on the verdict
//! self-check's records (`nsection` n = 2, `p,x,y`, 2 s at 2 kHz) a record whose piston
//! meets its stops shows them, at their travel, alone or beside another effect; records
//! without stops (clean, the other library effects, a hardening spring outside the library)
//! show none.

use stirling::models::data::Measured;
use stirling::models::diagnose::selfcheck::plan::plan;
use stirling::models::diagnose::selfcheck::record::record;
use stirling::models::diagnose::selfcheck::{Split, VerdictOptions};
use stirling::models::diagnose::stops_equation::{probe, seen, SEEN_SHARE};

/// The self-check's evaluation record `label` at `strength`.
fn case_record(label: &str, strength: f64) -> Measured {
    let opts = VerdictOptions::default();
    let case = plan(&opts)
        .unwrap()
        .into_iter()
        .find(|c| {
            c.split == Split::Eval && c.truth.label() == label && c.truth.strength() == strength
        })
        .unwrap_or_else(|| panic!("no evaluation case {label} x{strength}"));
    let dir = std::env::temp_dir().join(format!(
        "stirling-stops-eq-{}-{label}-{strength}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    let data = record(&opts, &case, &dir).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    data
}

/// The training block (the diagnosis's default: the first 60 %).
fn train(d: &Measured) -> (usize, usize) {
    (0, d.len() * 6 / 10)
}

#[test]
fn a_single_end_stop_is_seen_at_its_travel() {
    for strength in [1.0, 2.0] {
        let d = case_record("end_stops", strength);
        let s = seen(&d, train(&d).0, train(&d).1);
        assert_eq!(s.len(), 1, "{s:?}");
        assert_eq!(s[0].channel, "y");
        // the self-check's single stop sits at 5.5 mm (the smoothing takes a little off)
        assert!((s[0].travel.abs() - 5.5e-3).abs() < 0.25e-3, "{s:?}");
        assert!(
            s[0].coefficient < 0.0 && s[0].share > 5.0 * SEEN_SHARE,
            "{s:?}"
        );
    }
}

#[test]
fn an_end_stop_beside_another_effect_is_seen() {
    for label in [
        "end_stops+leak",
        "coulomb+end_stops",
        "end_stops+regen_quadratic",
    ] {
        let d = case_record(label, 1.0);
        let s = seen(&d, train(&d).0, train(&d).1);
        assert!(s.iter().any(|s| s.channel == "y"), "{label}: {s:?}");
    }
}

#[test]
fn records_without_stops_show_none() {
    for (label, strength) in [
        ("clean", 0.0),
        ("leak", 2.0),
        ("coulomb", 2.0),
        ("regen_quadratic", 2.0),
        ("outside:spring_cubic", 1.0),
    ] {
        let d = case_record(label, strength);
        let all = probe(&d, train(&d).0, train(&d).1).unwrap();
        let most = all.iter().map(|s| s.share).fold(0.0, f64::max);
        // an order of magnitude below the level: the stops' records give 0.08 and more
        assert!(most < SEEN_SHARE / 3.0, "{label}: {all:?}");
    }
}
