//! The verdict rule on hand-made rankings: a gross nominal gap is never `no_significant_gap`
//! even when no library direction is significant (the model misses the record for a reason
//! outside the library, or the record is not what the model measures).

use stirling::models::diagnose::verdict::{pick, Pick, Thresholds, GROSS_GAP};
use stirling::models::diagnose::RankEntry;

fn entry(effect: &str, p_value: f64) -> RankEntry {
    RankEntry {
        p_value,
        ..RankEntry::named(effect)
    }
}

#[test]
fn no_significant_candidate_is_no_gap_only_under_the_gross_bound() {
    let ranking = vec![entry("leak", 0.3), entry("coulomb", 0.8)];
    let th = Thresholds::at(0.01);
    assert!(matches!(
        pick(&ranking, 2, 1.2, &th),
        Pick::NoSignificantGap
    ));
    assert!(matches!(
        pick(&ranking, 2, GROSS_GAP * 0.99, &th),
        Pick::NoSignificantGap
    ));
    assert!(matches!(
        pick(&ranking, 2, GROSS_GAP * 4.0, &th),
        Pick::Unexplained
    ));
}

#[test]
fn a_significant_unfitted_candidate_is_unexplained() {
    let ranking = vec![entry("leak", 1e-9)];
    assert!(matches!(
        pick(&ranking, 1, 2.0, &Thresholds::at(0.01)),
        Pick::Unexplained
    ));
}
