//! Gap diagnosis self-check on a reduced set (cv1, 0.6 s at 1 kHz (the leak 1.2 s), one
//! strength, three candidates; the quadratic regenerator friction on nsection n = 2, 2 s at
//! 1 kHz). The diagnosis sees only the CSV the rig writes. The full self-check is
//! `stirling diagnose --self-check` (results in docs/diagnosis.md).

use stirling::models::diagnose::selfcheck::{self, SelfCheckOptions};
use stirling::models::diagnose::DiagnoseOptions;

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn reduced(effects: &[&str], clean: bool) -> SelfCheckOptions {
    let cands = strings(&["coulomb", "sensor_lag", "leak"]);
    SelfCheckOptions {
        effects: Some(strings(effects)),
        strengths: vec![1.0],
        t_end: 0.6,
        rate: 1000.0,
        clean,
        diagnose: DiagnoseOptions {
            effects: Some(cands),
            bootstrap: 200,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn assert_first(c: &selfcheck::Case) {
    assert_eq!(
        c.truth_rank,
        Some(1),
        "withheld effect not first (top {:?})",
        c.top
    );
}

fn log(c: &selfcheck::Case) {
    eprintln!(
        "{} -> {} (rank {:?}, closure {:?} [{:?}, {:?}], {:.1} s)",
        c.truth, c.verdict, c.truth_rank, c.closure_fraction, c.ci_low, c.ci_high, c.seconds
    );
}

#[test]
fn withheld_coulomb_friction_ranks_first_with_closure_interval() {
    let sc = selfcheck::run(&reduced(&["coulomb"], false), log).unwrap();
    let c = &sc.cases[0];
    assert_first(c);
    let (f, lo, hi) = (
        c.closure_fraction.unwrap(),
        c.ci_low.unwrap(),
        c.ci_high.unwrap(),
    );
    assert!(lo <= f && f <= hi && lo > 0.5, "closure {f} [{lo}, {hi}]");
    assert_eq!(c.verdict, "coulomb");
    // the JSON carries the documented keys
    let v = serde_json::to_value(c.diagnosis.as_deref().unwrap()).unwrap();
    for k in ["gap_before", "localization", "ranking", "verdict"] {
        assert!(v.get(k).is_some(), "missing `{k}`");
    }
    for k in [
        "effect",
        "score",
        "p_value",
        "delta_bic",
        "holdout_error",
        "closure_fraction",
        "ci_low",
        "ci_high",
        "params",
    ] {
        assert!(
            v["ranking"][0].get(k).is_some(),
            "ranking entry misses `{k}`"
        );
    }
    assert!(v["verdict"].get("effect").is_some() && v["verdict"].get("closure_fraction").is_some());
}

#[test]
fn clean_data_has_no_significant_gap() {
    let sc = selfcheck::run(&reduced(&[], true), log).unwrap();
    assert_eq!(sc.cases[0].verdict, "no_significant_gap");
}

#[test]
fn withheld_sensor_lag_ranks_first() {
    let sc = selfcheck::run(&reduced(&["sensor_lag"], false), log).unwrap();
    let c = &sc.cases[0];
    assert_first(c);
    let (f, lo, hi) = (
        c.closure_fraction.unwrap(),
        c.ci_low.unwrap(),
        c.ci_high.unwrap(),
    );
    assert!(lo <= f && f <= hi, "closure {f} [{lo}, {hi}]");
}

#[test]
fn withheld_leak_ranks_first_and_shows_in_the_parameter_shifts() {
    // the nominal calibration absorbs a leak into the heat-transfer coefficients, where the
    // score (a local test) does not see it; the verdict says the parameters moved, and with
    // every candidate fitted (`--fit-all`: the leak also from its own basin, the nominal
    // parameters reset) the leak ranks first (a longer record than the other cases: 0.36 s
    // of training hides the leak)
    let mut opts = SelfCheckOptions {
        t_end: 1.2,
        ..reduced(&["leak"], false)
    };
    opts.diagnose.fit_all = true;
    let sc = selfcheck::run(&opts, log).unwrap();
    let c = &sc.cases[0];
    assert_first(c);
    let d = c.diagnosis.as_deref().unwrap();
    assert!(
        d.verdict.reason.contains("may be absorbed"),
        "{}",
        d.verdict.reason
    );
    let far: Vec<_> = d
        .gap_before
        .shifts
        .iter()
        .filter(|s| s.prior_sd.is_some_and(|z| z.abs() > 2.0))
        .map(|s| s.name.as_str())
        .collect();
    assert!(
        far.contains(&"hh") || far.contains(&"hk"),
        "shifts {:?}",
        d.gap_before.shifts
    );
    let (_, truth, value, _, _) = &c.fitted[0];
    assert!(
        (value / truth - 1.0).abs() < 0.5,
        "Gleak {value:e}, truth {truth:e}"
    );
}

#[test]
fn withheld_quadratic_regenerator_friction_ranks_first_on_nsection() {
    // nsection n = 2 (the effect needs a regenerator), 2 s at 1 kHz; the competitors are the
    // candidates that damp or rescale the displacer like it
    let cands = strings(&["regen_quadratic", "sensor_gain", "coulomb"]);
    let opts = SelfCheckOptions {
        model: "nsection".into(),
        n: Some(2),
        t_end: 2.0,
        diagnose: DiagnoseOptions {
            effects: Some(cands),
            bootstrap: 200,
            ..Default::default()
        },
        ..reduced(&["regen_quadratic"], false)
    };
    let sc = selfcheck::run(&opts, log).unwrap();
    let c = &sc.cases[0];
    assert_first(c);
    let d = c.diagnosis.as_deref().unwrap();
    let entry = &d.ranking[0];
    assert!(entry.p_value < 0.01 / 3.0, "score p = {}", entry.p_value);
    // on this short record `Rq` is loosely determined and biased high (1.53e8 [1.04e8,
    // 2.02e8] against 1e8; a fit from the nominal parameters reset reaches 1.47e8 at a cost
    // 0.18 lower, the same flat valley): the effect is found and sized within a factor 2
    let (_, truth, value, lo, hi) = &c.fitted[0];
    assert!(
        (0.5..2.0).contains(&(value / truth)),
        "Rq {value} [{lo}, {hi}] vs {truth}"
    );
    assert!(c.closure_fraction.is_some() && c.ci_low.is_some() && c.ci_high.is_some());
}

#[test]
fn library_self_check_rejects_an_unknown_effect() {
    let opts = SelfCheckOptions {
        effects: Some(vec!["leak".into(), "bogus".into()]),
        ..Default::default()
    };
    let err = selfcheck::run_library(&opts, log).unwrap_err().to_string();
    assert!(err.contains("unknown effect `bogus`"), "{err}");
}

/// The verdict self-check, reduced for CI: on `nsection` n = 2, `p,x,y` records of 2 s at
/// 1 kHz, one withheld Coulomb friction, one clean record, one cause outside the library
/// (hardening springs) and the friction beside it (a mixed record: right when `unexplained`
/// or the friction with an unexplained remainder, never the friction as a full explanation),
/// all on the evaluation seeds (no tuning: the diagnosis's thresholds); candidates
/// `coulomb, sensor_lag, sensor_gain`. Each verdict must be right, and the confusion matrix
/// must say so.
#[test]
fn reduced_verdict_self_check_gets_the_verdicts_right() {
    use selfcheck::VerdictOptions;
    let opts = VerdictOptions {
        effects: Some(strings(&["coulomb"])),
        strengths: vec![1.0],
        outside: Some(strings(&["spring_cubic"])),
        seeds: (0, 1),
        clean: (0, 1),
        mixed_strength: Some(1.0),
        rate: 1000.0,
        diagnose: DiagnoseOptions {
            effects: Some(strings(&["coulomb", "sensor_lag", "sensor_gain"])),
            bootstrap: 200,
            ..Default::default()
        },
        ..Default::default()
    };
    let progress = |c: &selfcheck::outcome::Outcome, done: usize, total: usize| {
        eprintln!("[{done}/{total}] {}", selfcheck::report::case_row(c));
    };
    let v = selfcheck::run_verdicts(&opts, &progress).unwrap();
    assert_eq!(v.cases.len(), 4);
    for c in &v.cases {
        assert!(c.error.is_none(), "{:?}", c.error);
        assert!(
            selfcheck::plan::is_right(&c.expected, &c.verdict),
            "{}: {} (expected {}), top {:?}",
            c.label,
            c.verdict,
            c.expected,
            c.top
        );
    }
    let mixed = v.cases.last().unwrap();
    assert_eq!(mixed.label, "coulomb+outside:spring_cubic");
    assert_eq!(mixed.truth.class(), "mixed");
    assert_eq!((v.eval.right, v.eval.total), (4, 4));
    assert!(v
        .eval
        .classes
        .iter()
        .any(|(k, r, n)| k == "mixed" && (*r, *n) == (1, 1)));
    assert_eq!((v.eval.clean, v.eval.false_alarms), (1, 0));
    let md = selfcheck::report::markdown(&v);
    assert!(md.contains("| outside:spring_cubic | 0 | 1 | 0 |"), "{md}");
    // the outside cause moved the record at least as much as the friction did
    let sig = |l: &str| v.signatures.iter().find(|s| s.label == l).unwrap().clone();
    let (f, o) = (sig("coulomb"), sig("outside:spring_cubic"));
    assert!(
        o.freq.abs().max(o.x_amp.abs()) >= f.freq.abs().max(f.x_amp.abs()),
        "{o:?} vs {f:?}"
    );
}
