//! The diagnosis's verdict checked as a user reads it: printed, then the verdict (and the
//! effect it names) asserted, with the reason in the failure message.
#![allow(dead_code)]

use stirling::models::diagnose::Diagnosis;

/// `d`'s verdict is `verdict` naming `effect` (`None`: no effect named).
pub fn assert_verdict(d: &Diagnosis, label: &str, verdict: &str, effect: Option<&str>) {
    let v = &d.verdict;
    eprintln!("{label}: {} {:?} ({})", v.verdict, v.effect, v.reason);
    assert_eq!(v.verdict, verdict, "{label}: {}", v.reason);
    assert_eq!(v.effect.as_deref(), effect, "{label}: {}", v.reason);
}

/// The fitted value of parameter `name` of candidate `effect` in `d`'s ranking.
pub fn fitted(d: &Diagnosis, effect: &str, name: &str) -> f64 {
    let entry = d
        .ranking
        .iter()
        .find(|e| e.effect == effect)
        .unwrap_or_else(|| panic!("no candidate {effect}"));
    entry
        .params
        .iter()
        .find(|q| q.name == name)
        .unwrap_or_else(|| panic!("candidate {effect} has no parameter {name}"))
        .value
}
