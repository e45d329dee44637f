//! The diagnosis on a kinematic engine (the gamma LTD of `examples/engines/gamma_ltd.stirling`,
//! its effects named in the file: a second seal leak `leak cold -> room`, the foam's quadratic
//! friction `quadratic on link hot -> cold`, the transducer's `lag on sensor p`): rig records
//! as a lab takes them (`p` with 10 Pa noise and a 150 Pa offset, `theta` with 2 mrad, 10 s at
//! 100 Hz after a push and 5 s of settling). A withheld leak of 5x the piston's is named, its
//! strength's interval covering the truth, and so are a withheld 10 ms transducer lag, a
//! withheld quadratic friction of the foam and (on `gamma_ltd_plate.stirling`) a hot plate of
//! finite heat capacity; a clean record gives `no_significant_gap`; a record at 20 Hz is
//! refused by its rate
//! (docs/diagnosis.md, "Kinematic engines").

use std::path::Path;

use stirling::dsl::Model;
use stirling::models::data::Measured;
use stirling::models::diagnose::{diagnose, nominal_model, DiagnoseOptions, Diagnosis};
use stirling::models::rig::{measure, RigConfig};

fn gamma() -> (Box<dyn Model>, Vec<f64>) {
    engine("gamma_ltd.stirling")
}

/// An engine of `examples/engines/` and its defaults.
fn engine(file: &str) -> (Box<dyn Model>, Vec<f64>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(file);
    nominal_model(path.to_str().unwrap(), None).expect("the file loads")
}

/// A lab's record of the gamma LTD with `set` on its defaults, at `rate` Hz.
fn record(m: &dyn Model, set: &[(&str, f64)], rate: f64, seed: u64) -> Measured {
    record_fx(m, set, &[], rate, seed)
}

/// [`record`] with the rig's sensor effects `fx` (`tau_p=0.01`) on the readings.
fn record_fx(m: &dyn Model, set: &[(&str, f64)], fx: &[&str], rate: f64, seed: u64) -> Measured {
    let mut p = m.default_params();
    for (name, v) in set {
        p[m.param_index(name).expect("a parameter")] = *v;
    }
    let cfg = RigConfig {
        t_end: 10.0,
        settle: 5.0,
        rate,
        noise_p: 10.0,
        offset_p: 150.0,
        start: vec![("omega".into(), 17.7)],
        noise: vec![("theta".into(), 0.002)],
        channels: vec!["p".into(), "theta".into()],
        effects: fx.iter().map(|e| e.to_string()).collect(),
        seed,
        ..Default::default()
    };
    measure(m, &p, &cfg).expect("the rig records the engine")
}

fn diagnosed(set: &[(&str, f64)], seed: u64) -> Diagnosis {
    diagnosed_fx(set, &[], seed)
}

/// [`diagnosed`] on a record with the sensor effects `fx`.
fn diagnosed_fx(set: &[(&str, f64)], fx: &[&str], seed: u64) -> Diagnosis {
    diagnosed_on("gamma_ltd.stirling", (set, fx), None, seed)
}

/// The diagnosis of a record of the engine `file` with `set` and the sensor effects `fx`,
/// over the candidates `effects` (`None`: every one the file names).
fn diagnosed_on(
    file: &str,
    (set, fx): (&[(&str, f64)], &[&str]),
    effects: Option<&[&str]>,
    seed: u64,
) -> Diagnosis {
    let (m, p0) = engine(file);
    let data = record_fx(m.as_ref(), set, fx, 100.0, seed);
    let opts = DiagnoseOptions {
        bootstrap: 200,
        effects: effects.map(|e| e.iter().map(|s| s.to_string()).collect()),
        ..Default::default()
    };
    let d = diagnose(m.as_ref(), &p0, &data, &opts).expect("diagnosed");
    eprintln!(
        "{set:?} seed {seed}: {} {:?} remainder {} (gap {:.3}; {}) in {:.1} s",
        d.verdict.verdict,
        d.verdict.effects,
        d.verdict.unexplained_remainder,
        d.verdict.gap,
        d.verdict.reason,
        d.seconds
    );
    for r in &d.ranking {
        eprintln!(
            "  {:10} p {:.2e} dBIC {:?} closure {:?} [{:?}, {:?}] {:?}",
            r.effect, r.p_value, r.delta_bic, r.closure_fraction, r.ci_low, r.ci_high, r.params
        );
    }
    d
}

#[test]
fn a_withheld_leak_on_the_gamma_engine_is_named() {
    let truth = 2e-9;
    for seed in [7, 3] {
        let d = diagnosed(&[("Gleak_cold_room", truth)], seed);
        assert_eq!(d.verdict.verdict, "effect", "{:?}", d.verdict);
        assert_eq!(d.verdict.effects, ["leak"], "{:?}", d.verdict);
        let step = &d.steps[0];
        let g = step
            .params
            .iter()
            .find(|q| q.name == "Gleak_cold_room")
            .expect("the leak's strength");
        assert!(g.ci_low <= truth && truth <= g.ci_high, "{g:?}");
        assert!(step.closure.ci_low > 0.5, "{:?}", step.closure);
        // the engine still runs with it (the record cycles), and the verdict says where the
        // free run is not measured
        assert!(d.simulation_gap_note.is_some());
    }
}

#[test]
fn a_withheld_transducer_lag_on_the_gamma_engine_is_named() {
    // 10 ms against a cycle of 360 ms (a hobby transducer behind a tube): the file's
    // `effect lag on sensor p;`, fitted on the driven stage itself
    let truth = 0.01;
    let d = diagnosed_fx(&[], &["tau_p=0.01"], 7);
    assert_eq!(d.verdict.effects, ["lag"], "{:?}", d.verdict);
    let step = &d.steps[0];
    let tau = step
        .params
        .iter()
        .find(|q| q.name == "tau_p")
        .expect("tau_p");
    assert!(tau.ci_low <= truth && truth <= tau.ci_high, "{tau:?}");
    assert!(step.closure.ci_low > 0.5, "{:?}", step.closure);
    // the reason gives the held-out error after the lag (it printed NaN: the lag is not
    // refitted like a model effect, its entry holds the number)
    assert!(!d.verdict.reason.contains("NaN"), "{}", d.verdict.reason);
    assert!(!d.verdict.unexplained_remainder, "{}", d.verdict.reason);
}

/// The strength `name` of the first step, which must cover `truth`.
fn covers(d: &Diagnosis, name: &str, truth: f64) {
    let q = d.steps[0]
        .params
        .iter()
        .find(|q| q.name == name)
        .expect("the strength");
    assert!(q.ci_low <= truth && truth <= q.ci_high, "{q:?}");
}

#[test]
fn a_withheld_foam_friction_is_named() {
    // quadratic friction in the foam at 3e9 Pa s^2/kg^2: the calibration takes it into the
    // linear `Rf` and the fit from the null stays there; from its typical strength (the
    // second start of a strength left at its null) it is found: 3.07e9 and 2.96e9
    let truth = 3e9;
    for seed in [7, 3] {
        let d = diagnosed(&[("Rq_hot_cold", truth)], seed);
        assert_eq!(d.verdict.effects, ["quadratic"], "{:?}", d.verdict);
        covers(&d, "Rq_hot_cold", truth);
        assert!(d.steps[0].closure.ci_low > 0.5, "{:?}", d.steps[0].closure);
    }
}

#[test]
fn a_foam_friction_outside_the_candidates_is_not_called_no_gap() {
    // the same record diagnosed over the leak and the lag only: no candidate's score is
    // significant, but the calibrated model misses the held-out pressure by 2.3 noise
    // variances (clean records: 0.83 to 1.12); the verdict says the gap is there and not
    // explained, not that there is none
    let d = diagnosed_on(
        "gamma_ltd.stirling",
        (&[("Rq_hot_cold", 3e9)], &[]),
        Some(&["leak", "lag"]),
        7,
    );
    assert_eq!(d.verdict.verdict, "unexplained", "{:?}", d.verdict);
    assert!(d.verdict.gap > 1.5, "{:?}", d.verdict);
    assert!(
        d.verdict.reason.contains("more than noise alone"),
        "{}",
        d.verdict.reason
    );
}

#[test]
fn a_hot_plate_of_finite_heat_capacity_is_named() {
    // `gamma_ltd_plate.stirling`: the plate a wall of inverse heat capacity `kh_hot_plate`;
    // a plate of 1 J/K, its temperature at the window start fitted like the masses (from the
    // rest state's, `p` fitted to 85 % with the capacity held at the truth) and the capacity
    // fitted from its typical value (from its null it stays there): 1.54 [0.83, 2.25]
    let truth = 1.0;
    let d = diagnosed_on(
        "gamma_ltd_plate.stirling",
        (&[("kh_hot_plate", truth)], &[]),
        None,
        7,
    );
    assert_eq!(d.verdict.effects, ["heater_input"], "{:?}", d.verdict);
    covers(&d, "kh_hot_plate", truth);
    // and a fixed plate is not taken for one
    let d = diagnosed_on("gamma_ltd_plate.stirling", (&[], &[]), None, 7);
    assert_eq!(d.verdict.verdict, "no_significant_gap", "{:?}", d.verdict);
}

#[test]
fn more_bearing_friction_is_no_gas_effect_and_the_flywheel_check_finds_it() {
    // three times the file's Coulomb torque of the bearings (3e-5 N m): the engine slower,
    // its gas as the file's
    let d = diagnosed(&[("Tc", 9e-5)], 7);
    assert!(d.verdict.effects.is_empty(), "{:?}", d.verdict);
    let f = d
        .flywheel
        .as_ref()
        .expect("the gamma file's flywheel has friction");
    assert!(f.differs, "{f:?}");
    // the torque at the record's speeds: the file's with its Coulomb part 6e-5 N m larger
    // (tanh(omega / w_eps) = 1 at these speeds)
    let truth = f.file_value + 6e-5;
    assert!(
        f.ci_low < truth && truth < f.ci_high,
        "{f:?}: truth {truth:.4e}"
    );
    assert!(
        d.verdict.reason.contains("differs from the file's"),
        "{}",
        d.verdict.reason
    );
}

#[test]
fn a_clean_gamma_record_has_no_significant_gap() {
    for seed in [7, 3] {
        let d = diagnosed(&[], seed);
        assert_eq!(d.verdict.verdict, "no_significant_gap", "{:?}", d.verdict);
        assert!(d.verdict.effects.is_empty() && !d.verdict.unexplained_remainder);
        assert!(d.steps.is_empty());
        // the flywheel's friction is the file's
        let f = d.flywheel.as_ref().expect("checked");
        assert!(!f.differs, "seed {seed}: {f:?}");
    }
}

#[test]
fn a_record_too_slow_for_the_flywheel_is_refused_by_its_rate() {
    let (m, p0) = gamma();
    let data = record(m.as_ref(), &[], 20.0, 7);
    let err = diagnose(m.as_ref(), &p0, &data, &DiagnoseOptions::default())
        .expect_err("refused")
        .to_string();
    for part in ["samples per revolution", "at least 10", "Hz or more"] {
        assert!(err.contains(part), "{err}");
    }
    assert!(!err.contains("does not move"), "{err}");
}
