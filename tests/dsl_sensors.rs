//! Sensors declared with a model (`sensor name: STATE "unit";`): the family's, a derived
//! model's additions and replacements, and the run-time resolution of array elements.

use stirling::dsl::{Closure, Model, SensorInfo};
use stirling::models::family::{Cv1, Cv2, NSection};
use stirling::stirling_model;

stirling_model! {
    /// The nsection engine probed otherwise: the cold transducer in kPa, no hot one, one in
    /// regenerator section 2 and a velocity sensor on the displacer.
    pub model Probed extends stirling::models::nsection_engine {
        name "probed";
        replace sensor p: P_cold "kPa";
        remove sensor p_hot;
        sensor p_r2: P_regen[2];
        sensor v: v;
        replace free kd, hr;
    }
}

stirling_model! {
    /// The nsection engine with its `p` transducer moved to the hot space.
    pub model HotP extends stirling::models::nsection_engine {
        name "hot_p";
        replace sensor p: P_hot "Pa";
    }
}

fn names(m: &dyn Model) -> Vec<&'static str> {
    m.sensors().iter().map(|s| s.name).collect()
}

#[test]
fn the_family_declares_the_seeds_sensors() {
    let ns = NSection::new(3, Closure::Full).unwrap();
    assert_eq!(names(&ns), ["x", "y", "p", "p_hot"]);
    let st = ns.state_names();
    for (s, want) in [("x", "x"), ("y", "y"), ("p", "P_cold"), ("p_hot", "P_hot")] {
        let k = ns.sensor_state(s).unwrap().unwrap();
        assert_eq!(st[k], want, "sensor {s}");
    }
    assert_eq!(ns.sensor_state("q"), None);
    let cv1 = Cv1::new(1, Closure::Full).unwrap();
    assert_eq!(names(&cv1), ["x", "y", "p"]);
    assert_eq!(
        cv1.state_names()[cv1.sensor_state("p").unwrap().unwrap()],
        "P_gas"
    );
    let cv2 = Cv2::new(1, Closure::Frozen).unwrap();
    assert_eq!(names(&cv2), ["x", "y", "p", "p_hot"]);
}

#[test]
fn a_derived_model_adds_replaces_and_removes_sensors() {
    let m = Probed::new(4, Closure::Full).unwrap();
    assert_eq!(names(&m), ["x", "y", "p", "p_r2", "v"]);
    let p = m.sensors().iter().find(|s| s.name == "p").unwrap();
    assert_eq!(
        *p,
        SensorInfo {
            name: "p",
            state: "P_cold",
            unit: "kPa"
        }
    );
    // units default to the state's
    let r2 = m.sensors().iter().find(|s| s.name == "p_r2").unwrap();
    assert_eq!((r2.state, r2.unit), ("P_regen[2]", "Pa"));
    assert_eq!(
        m.sensors().iter().find(|s| s.name == "v").unwrap().unit,
        "m/s"
    );
    let st = m.state_names();
    assert_eq!(st[m.sensor_state("p_r2").unwrap().unwrap()], "P_regen[2]");
}

#[test]
fn an_element_beyond_n_resolves_to_no_state() {
    let m = Probed::new(2, Closure::Full).unwrap();
    assert_eq!(m.sensor_state("p_r2"), Some(None));
}

/// The two stages read `p` from the last CV: a model that declares it elsewhere is refused
/// by name (not fitted as if it were on the cold side); the family and a model that only adds
/// sensors pass.
#[test]
fn identification_refuses_a_seed_channel_declared_elsewhere() {
    use stirling::models::data::Measured;
    use stirling::models::fit::{self, supported::check_sensors, FitError};
    let m = HotP::new(2, Closure::Full).unwrap();
    let err = fit::identify(
        &m,
        &m.default_params(),
        &Measured::default(),
        &Default::default(),
    )
    .expect_err("p declared on the hot side");
    assert!(
        matches!(&err, FitError::SensorPlace { channel: "p", state, expected, .. }
            if state == "P_hot" && expected == "P_cold"),
        "{err}"
    );
    assert!(err.to_string().contains("`p` on P_hot"), "{err}");
    assert!(check_sensors(&Probed::new(3, Closure::Full).unwrap()).is_ok());
    for entry in stirling::models::model::registry::FAMILY {
        for closure in [Closure::Full, Closure::Frozen] {
            let family = stirling::models::model::registry::build(entry.name, None, closure)
                .expect("family member");
            assert!(check_sensors(family.as_ref()).is_ok(), "{}", entry.name);
        }
    }
}

/// `free a, b;` declares what a fit frees by default: the family's is the seed's list (the
/// parameters a member's equations lack, like `Rf` in `cv1`, are left out by the fit), a
/// derived model replaces it.
#[test]
fn the_free_parameters_come_from_the_declaration() {
    use stirling::models::fit::classify::default_free;
    let ns = NSection::new(2, Closure::Full).unwrap();
    let seed = ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"];
    assert_eq!(ns.declared_free(), seed);
    assert_eq!(default_free(&ns, &ns.default_params()), seed);
    let cv1 = Cv1::new(1, Closure::Full).unwrap();
    assert_eq!(default_free(&cv1, &cv1.default_params()), &seed[..6]);
    let m = Probed::new(3, Closure::Full).unwrap();
    assert_eq!(m.declared_free(), ["kd", "hr"]);
    assert_eq!(default_free(&m, &m.default_params()), ["kd", "hr"]);
}
