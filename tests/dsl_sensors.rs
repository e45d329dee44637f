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

stirling_model! {
    /// The nsection engine with expression sensors: the pressure drop across the regenerator,
    /// an alternator-like voltage on the piston's velocity, and a nonlinear mix of states and
    /// parameters that exercises every derivative rule the outputs use.
    pub model Expressed extends stirling::models::nsection_engine {
        name "expressed";
        params {
            /// velocity-to-voltage constant of a moving-magnet alternator
            Kv: 12.0 "V s/m",
        }
        sensor dp: P_hot - P_cold "Pa";
        sensor volt: Kv * w "V";
        sensor mix: sqrt(P_regen[1] * P_cold) / Pmean + kd * x.powi(2) - exp(-v * v) + (y / x).tanh() "1";
    }
}

stirling_model! {
    /// The nsection engine with its `p` channel declared as a pressure difference.
    pub model DiffP extends stirling::models::nsection_engine {
        name "diff_p";
        replace sensor p: P_cold - P_hot "Pa";
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
            expr: "",
            reads: &["P_cold"],
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
    // an expression under a seed channel's name is refused the same way, by its expression
    let m = DiffP::new(2, Closure::Full).unwrap();
    let err = fit::identify(
        &m,
        &m.default_params(),
        &Measured::default(),
        &Default::default(),
    )
    .expect_err("p declared as an expression");
    assert!(err.to_string().contains("`p` on P_cold - P_hot;"), "{err}");
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

/// An expression sensor declares its output: printed over the states and parameters, with
/// the states it reads; at run time its value is the expression at the state.
#[test]
fn an_expression_sensor_outputs_its_expression() {
    use stirling::dsl::Observation;
    let m = Expressed::new(3, Closure::Full).unwrap();
    assert_eq!(names(&m), ["x", "y", "p", "p_hot", "dp", "volt", "mix"]);
    let info = |n: &str| *m.sensors().iter().find(|s| s.name == n).unwrap();
    let dp = info("dp");
    assert_eq!((dp.state, dp.expr, dp.unit), ("", "P_hot - P_cold", "Pa"));
    assert_eq!(dp.reads, ["P_hot", "P_cold"]);
    assert_eq!(info("volt").definition(), "Kv * w");
    assert_eq!(info("mix").reads, ["P_regen[1]", "P_cold", "x", "v", "y"]);
    assert_eq!(
        info("mix").expr,
        "sqrt(P_regen[1] * P_cold) / Pmean + kd * x^2 - exp(-v * v) + tanh(y / x)"
    );
    assert_eq!(m.sensor_state("dp"), Some(None));
    let p = m.default_params();
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    let st = m.state_names();
    let at = |n: &str| st.iter().position(|s| s == n).unwrap();
    x[at("P_hot")] += 1234.0;
    x[at("w")] = 0.7;
    let obs = |n: &str| Observation::sensor(&m, n).unwrap();
    assert_eq!(
        obs("dp").value(&m, &p, &x),
        x[at("P_hot")] - x[at("P_cold")]
    );
    assert_eq!(obs("volt").value(&m, &p, &x), 12.0 * 0.7);
    // a state sensor is its state
    assert_eq!(obs("p").as_state(), Some(at("P_cold")));
    assert_eq!(obs("dp").as_state(), None);
}

/// The generated gradient of every sensor output, in the states it reads and in the
/// parameters, against central differences at a state away from equilibrium.
#[test]
fn expression_sensor_gradients_match_finite_differences() {
    use stirling::dsl::Observation;
    let m = Expressed::new(3, Closure::Full).unwrap();
    let p = m.default_params();
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    let st = m.state_names();
    for (name, v) in [("x", 2e-3), ("v", 0.3), ("y", -1.5e-3), ("w", 0.7)] {
        x[st.iter().position(|s| s == name).unwrap()] = v;
    }
    for (i, s) in st.iter().enumerate() {
        if s.starts_with("P_") {
            x[i] *= 1.0 + 0.01 * i as f64;
        }
    }
    for s in m.sensors() {
        let o = Observation::sensor(&m, s.name).unwrap();
        let (mut dv, mut dp) = (vec![0.0; o.reads().len()], vec![0.0; p.len()]);
        let y = o.gradient(&m, &p, &x, &mut dv, &mut dp);
        assert_eq!(y, o.value(&m, &p, &x));
        for (r, &i) in o.reads().iter().enumerate() {
            let h = 1e-6 * x[i].abs().max(1e-3);
            let (mut a, mut b) = (x.clone(), x.clone());
            a[i] += h;
            b[i] -= h;
            let fd = (o.value(&m, &p, &a) - o.value(&m, &p, &b)) / (2.0 * h);
            assert!(
                (dv[r] - fd).abs() <= 1e-6 * fd.abs().max(1e-6 * y.abs().max(1.0)),
                "sensor {}: d/d{} = {} vs fd {fd}",
                s.name,
                st[i],
                dv[r]
            );
        }
        for j in 0..p.len() {
            let h = 1e-6 * p[j].abs().max(1e-6);
            let (mut a, mut b) = (p.clone(), p.clone());
            a[j] += h;
            b[j] -= h;
            let fd = (o.value(&m, &a, &x) - o.value(&m, &b, &x)) / (2.0 * h);
            assert!(
                (dp[j] - fd).abs() <= 1e-6 * fd.abs().max(1e-9),
                "sensor {}: d/d{} = {} vs fd {fd}",
                s.name,
                m.params()[j].name,
                dp[j]
            );
        }
    }
}

/// A record's channel cannot be observed where the model has no state for it: an element
/// beyond `n` is refused by name, as is an undeclared sensor.
#[test]
fn an_observation_refuses_what_the_model_cannot_output() {
    use stirling::dsl::{Observation, ObserveError};
    let m = Expressed::new(1, Closure::Full).unwrap();
    let err = Observation::sensor(&m, "mix").unwrap_err();
    assert!(
        matches!(&err, ObserveError::Absent { sensor, state, n: 1, .. } if sensor == "mix" && state == "P_regen[1]"),
        "{err}"
    );
    let err = Observation::sensor(&m, "volts").unwrap_err();
    assert!(
        err.to_string().contains("declares no sensor `volts`"),
        "{err}"
    );
    assert!(err.to_string().contains("volt"), "{err}");
}

stirling_model! {
    /// A sensor whose expression leaves its domain: the square root of the displacer's
    /// position, which swings negative.
    pub model Rooted extends stirling::models::nsection_engine {
        name "rooted";
        sensor root: sqrt(x) "m";
    }
}

/// The rig refuses a channel whose expression is not a number along the run, naming the
/// channel and the time, instead of writing NaN into the record.
#[test]
fn the_rig_refuses_a_sensor_that_is_not_a_number() {
    use stirling::models::rig::{measure, RigConfig, RigError};
    let m = Rooted::new(2, Closure::Full).unwrap();
    let cfg = RigConfig {
        t_end: 0.2,
        channels: ["p", "x", "root"].map(String::from).to_vec(),
        ..Default::default()
    };
    let err = measure(&m, &m.default_params(), &cfg).unwrap_err();
    assert!(
        matches!(&err, RigError::NonFinite { channel, .. } if channel == "root"),
        "{err}"
    );
    assert!(err.to_string().contains("not a number at t ="), "{err}");
}

/// A declared pressure sensor inside the working gas (`sensor p_r2: P_regen[2];`, a
/// regenerator section) is an output of stage 2 with its own offset, next to `p`: the
/// identification fits it, recovers the parameters with intervals that cover the truth and
/// reports its offset; the interval of the regenerator's heat transfer `hr` narrows (0.21
/// against 0.29 W/(m^2 K) on `p` alone).
#[test]
fn a_regenerator_sensor_is_fitted_by_the_gas_stage() {
    use stirling::models::fit::{self, FitOptions};
    use stirling::models::rig::{measure, RigConfig};
    let m = Probed::new(4, Closure::Full).unwrap();
    let truth = m.default_params();
    let record = |channels: &[&str]| {
        let cfg = RigConfig {
            t_end: 3.0,
            x0: 5e-4,
            offset_p: 50.0,
            seed: 3,
            channels: channels.iter().map(|c| c.to_string()).collect(),
            ..Default::default()
        };
        measure(&m, &truth, &cfg).expect("measured")
    };
    let mut p0 = truth.clone();
    for (k, f) in [("kd", 1.02), ("hr", 0.85)] {
        p0[m.param_index(k).unwrap()] *= f;
    }
    let opts = FitOptions::default();
    let with = fit::identify(&m, &p0, &record(&["p", "x", "y", "p_r2"]), &opts).expect("fitted");
    let s2 = with.stage2.as_ref().expect("stage 2");
    let channels: Vec<&str> = s2.fits.iter().map(|f| f.channel.as_str()).collect();
    assert!(channels.contains(&"p_r2"), "{channels:?}");
    let off = with.offsets.get("p_r2");
    assert!((off - 50.0).abs() < 30.0, "p_r2 offset {off}");
    let without = fit::identify(&m, &p0, &record(&["p", "x", "y"]), &opts).expect("fitted");
    for k in ["kd", "hr"] {
        let t = truth[m.param_index(k).unwrap()];
        let (a, b) = (with.estimate(k).unwrap(), without.estimate(k).unwrap());
        eprintln!(
            "{k}: with p_r2 {:.5e} [{:.5e}, {:.5e}], without {:.5e} [{:.5e}, {:.5e}], truth {t:.5e}",
            a.value, a.ci_low, a.ci_high, b.value, b.ci_low, b.ci_high
        );
        assert!(a.covers(t), "{k} with p_r2: {a:?}");
    }
    // the section's pressure carries information on its heat transfer
    let width = |id: &fit::Identification| {
        let e = id.estimate("hr").unwrap();
        e.ci_high - e.ci_low
    };
    assert!(
        width(&with) < 0.9 * width(&without),
        "hr: {} vs {}",
        width(&with),
        width(&without)
    );
}
