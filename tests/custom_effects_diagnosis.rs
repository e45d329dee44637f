//! The diagnosis on a declared engine (`examples/custom_topology.rs`) whose augmented members
//! name a heater head as a port effect (`effect heater_input on port hot.hot;`) and a lag on
//! one sensor (`effect lag on sensor p_bounce;`): the library's wall-state and sensor effects
//! are effects of any engine, named where they act.

#[path = "../examples/custom_topology.rs"]
#[allow(dead_code)]
#[macro_use]
mod ex;

mod common;

use common::startup::start_up_record;
use common::verdict::{assert_verdict, fitted};
use stirling::dsl::Closure;
use stirling::models::diagnose::{diagnose, DiagnoseOptions};
use stirling::stirling_model;

stirling_model! {
    /// The alternator engine with a heater head of finite capacity and Coulomb friction on
    /// the piston, at their null.
    pub model HeatedFx extends alternator_engine {
        name "alternator_engine_heated_fx";
        effect heater_input on port hot.hot;
        effect coulomb on piston;
    }
}

stirling_model! {
    /// The alternator engine with a lag on its bounce-space transducer and Coulomb friction
    /// on the piston, at their null.
    pub model LaggedFx extends alternator_engine {
        name "alternator_engine_lagged_fx";
        effect lag on sensor p_bounce;
        effect coulomb on piston;
    }
}

stirling_model! {
    /// The alternator engine with Coulomb friction on the piston whose strength the model
    /// bounds (`in 0.0..0.3`): the diagnosis's joint fit stays inside.
    pub model BoundedFx extends alternator_engine {
        name "alternator_engine_bounded_fx";
        params {
            /// Coulomb friction force on the piston, at most 0.3 N
            Fc_piston: 0.0 "N" in 0.0..0.3,
        }
        effect coulomb on piston;
    }
}

fn record(kh: f64) -> (HeatedFx, Vec<f64>, stirling::models::data::Measured) {
    let m = HeatedFx::new(2, Closure::Full).unwrap();
    start_up_record(m, &[("kh_hot_hot", kh)], &[])
}

/// A heater head of finite capacity withheld from the record (`kh_hot_hot` = 0.4 K/J: a
/// 2.5 J/K head fed through 0.5 W/K, which sags by several kelvin a second under the heat
/// the gas draws) is named by the diagnosis, its strength recovered; a clean record gives
/// `no_significant_gap`. At the library's typical 0.04 K/J (the family's head, time constant
/// 50 s) a 2 s record does not show it (p = 4.3e-3 against the threshold 3.3e-3: no
/// significant gap), at 0.2 it is significant (p = 2e-17) but closes the gap by less than
/// half with confidence (`unexplained`, naming it first): the head's temperature at the
/// held-out block's start is not measured, so the free run starts it at its rest.
#[test]
fn the_diagnosis_names_a_withheld_heater_head() {
    let opts = options(&["heater_input", "coulomb", "sensor_lag"], 200);
    let (m, p0, rec) = record(0.4);
    let d = diagnose(&m, &p0, &rec, &opts).expect("diagnosed");
    assert_verdict(&d, "heater", "effect", Some("heater_input"));
    let kh = fitted(&d, "heater_input", "kh_hot_hot");
    assert!((0.3..0.6).contains(&kh), "kh_hot_hot {kh} (truth 0.4)");
    let (m, p0, rec) = record(0.0);
    let d = diagnose(&m, &p0, &rec, &opts).expect("diagnosed");
    assert_verdict(&d, "clean", "no_significant_gap", None);
}

/// A lag of 3 ms on the bounce-space transducer alone (`effect lag on sensor p_bounce;`,
/// parameter `tau_p_bounce`), withheld: the diagnosis names `lag`, not the library's
/// `sensor_lag` (which lags every pressure transducer), and recovers its time constant.
#[test]
fn the_diagnosis_names_a_lag_on_one_sensor() {
    let opts = options(&["lag", "sensor_lag", "coulomb"], 200);
    let m = LaggedFx::new(2, Closure::Full).unwrap();
    let (m, p0, rec) = start_up_record(m, &[], &[("tau_p_bounce", 3e-3)]);
    let d = diagnose(&m, &p0, &rec, &opts).expect("diagnosed");
    assert_verdict(&d, "lag", "effect", Some("lag"));
    let tau = fitted(&d, "lag", "tau_p_bounce");
    assert!(
        (2e-3..4e-3).contains(&tau),
        "tau_p_bounce {tau} (truth 3e-3)"
    );
    let (m, p0, rec) = start_up_record(m, &[], &[]);
    let d = diagnose(&m, &p0, &rec, &opts).expect("diagnosed");
    assert_verdict(&d, "clean", "no_significant_gap", None);
}

/// A range the model declares for an effect's strength holds in the diagnosis's joint fit:
/// with 0.5 N of piston friction withheld and `Fc_piston` declared in `0.0..0.3`, the fitted
/// strength ends inside (at the bound), where unbounded it reaches 0.39 N.
#[test]
fn the_joint_fit_stays_inside_declared_bounds() {
    let m = BoundedFx::new(2, Closure::Full).unwrap();
    let (m, p0, rec) = start_up_record(m, &[("Fc_piston", 0.5)], &[]);
    let d = diagnose(&m, &p0, &rec, &options(&["coulomb"], 100)).expect("diagnosed");
    let fc = fitted(&d, "coulomb", "Fc_piston");
    assert!(fc <= 0.3, "Fc_piston {fc} outside 0.0..0.3");
    assert!(fc > 0.25, "Fc_piston {fc}: pushed to the bound by the data");
}

/// The diagnosis of `effects`, every candidate fitted.
fn options(effects: &[&str], bootstrap: usize) -> DiagnoseOptions {
    DiagnoseOptions {
        effects: Some(effects.iter().map(|e| e.to_string()).collect()),
        bootstrap,
        fit_all: true,
        ..Default::default()
    }
}
