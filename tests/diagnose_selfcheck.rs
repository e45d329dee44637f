//! Gap diagnosis self-check on a reduced set (cv1, 0.5 s at 1 kHz, one strength per effect,
//! three candidates): the withheld effect ranks first with its closure fraction and interval,
//! and clean data gives `no_significant_gap`. The diagnosis sees only the CSV the rig writes.
//! The full self-check is `stirling diagnose --self-check` (docs/diagnosis.md).

use stirling::models::diagnose::selfcheck::{self, SelfCheckOptions};
use stirling::models::diagnose::DiagnoseOptions;

#[test]
fn withheld_effects_rank_first_and_clean_data_has_no_gap() {
    let cands: Vec<String> = ["sensor_lag", "coulomb", "leak"].iter().map(|s| s.to_string()).collect();
    let opts = SelfCheckOptions {
        effects: Some(vec!["sensor_lag".into(), "coulomb".into()]),
        strengths: vec![1.0],
        t_end: 0.5,
        rate: 1000.0,
        diagnose: DiagnoseOptions { effects: Some(cands), max_fit: 2, newton_iters: 4, bootstrap: 200, ..Default::default() },
        ..Default::default()
    };
    let sc = selfcheck::run(&opts, |c| eprintln!("{} -> {} (rank {:?}, closure {:?} [{:?}, {:?}], {:.1} s)", c.truth, c.verdict, c.truth_rank, c.closure_fraction, c.ci_low, c.ci_high, c.seconds)).unwrap();
    eprintln!("{}", selfcheck::matrix_markdown(&sc));
    for c in &sc.cases {
        if c.truth == "none" {
            assert_eq!(c.verdict, "no_significant_gap", "clean data");
        } else {
            assert_eq!(c.truth_rank, Some(1), "{}: withheld effect not first (top {:?})", c.truth, c.top);
            let (f, lo, hi) = (c.closure_fraction.unwrap(), c.ci_low.unwrap(), c.ci_high.unwrap());
            assert!(lo <= f && f <= hi && lo > 0.2, "{}: closure {f} [{lo}, {hi}]", c.truth);
            assert_eq!(c.verdict, c.truth);
        }
    }
    // the JSON carries the documented keys
    let d = sc.cases[1].diagnosis.as_ref().unwrap();
    let v = serde_json::to_value(d.as_ref()).unwrap();
    for k in ["gap_before", "localization", "ranking", "verdict"] {
        assert!(v.get(k).is_some(), "missing `{k}`");
    }
    for k in ["effect", "score", "p_value", "delta_bic", "holdout_error", "closure_fraction", "ci_low", "ci_high", "params"] {
        assert!(v["ranking"][0].get(k).is_some(), "ranking entry misses `{k}`");
    }
    assert!(v["verdict"].get("effect").is_some() && v["verdict"].get("closure_fraction").is_some());
}
