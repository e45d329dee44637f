//! `effect` items (docs/custom-topologies.md, "Effects"): an effect named where it acts is the
//! model with the effect's term written by hand (same states, parameters, defaults, right-hand
//! side and Jacobians, the effect switched on or off), it is absent at its null bit for bit,
//! its Jacobians match finite differences, and the model lists it in `Model::effect_sites`,
//! from which the diagnosis takes its candidates under the model's own parameter names.

mod common;

use stirling::dsl::{Closure, EffectSite, Model};
use stirling::models::effects;
use stirling::stirling_model;

stirling_model! {
    /// `nsection` with Coulomb friction on the piston, end stops on the displacer and a seal
    /// leak from the cold space into the bounce space, named where they act.
    pub model Named extends stirling::models::nsection_engine {
        modify space bounce { temperature: Tk }
        effect coulomb on piston;
        effect end_stops on displacer;
        effect leak cold -> bounce;
        effect orifice_leak cold -> bounce;
        effect quadratic on link hot -> regen[0];
    }
}

stirling_model! {
    /// The same, written by hand.
    pub model Hand extends stirling::models::nsection_engine {
        modify space bounce { temperature: Tk }
        params {
            /// Coulomb friction force on piston (0: none)
            Fc_piston: 0.0 "N",
            /// velocity scale of the smoothed Coulomb friction
            v_eps: 1.0e-3 "m/s",
            /// end-stop contact stiffness on displacer (0: no stops)
            kc_displacer: 0.0 "N/m",
            /// travel of displacer to its end stops
            xmax: 0.01 "m",
            /// seal-leak conductance cold -> bounce (0: no leak)
            Gleak_cold_bounce: 0.0 "kg/(s Pa)",
            /// orifice seal-leak coefficient cold -> bounce (0: no leak)
            Co_cold_bounce: 0.0 "kg/(s Pa^0.5)",
            /// width of the orifice law's linear core
            dP0: 50.0 "Pa",
            /// quadratic flow resistance of link hot -> regen[0] (0: linear only)
            Rq_hot_regen: 0.0 "Pa s^2/kg^2",
        }
        modify link hot -> regen[0] { quadratic: Rq_hot_regen }
        modify body piston { force: -Fc_piston * tanh(w / v_eps) }
        modify body displacer { force: -kc_displacer * ((abs(x) - xmax) + abs(abs(x) - xmax)) / 2.0 * sign(x) }
        link cold -> bounce { conductance: Gleak_cold_bounce }
        link cold -> bounce { orifice: Co_cold_bounce, dp0: dP0 }
    }
}

stirling_model! {
    /// The nominal model the effects are added to.
    pub model Plain extends stirling::models::nsection_engine {
        modify space bounce { temperature: Tk }
    }
}

/// The parameters `Named` declares, in order, with their docs and units.
#[test]
fn the_effects_declare_their_parameters_at_their_null() {
    let m = Named::new(2, Closure::Full).unwrap();
    let added: Vec<(&str, f64, &str)> = m
        .params()
        .iter()
        .skip(Plain::new(2, Closure::Full).unwrap().params().len())
        .map(|p| (p.name, p.default, p.unit))
        .collect();
    assert_eq!(
        added,
        [
            ("Fc_piston", 0.0, "N"),
            ("v_eps", 1.0e-3, "m/s"),
            ("kc_displacer", 0.0, "N/m"),
            ("xmax", 0.01, "m"),
            ("Gleak_cold_bounce", 0.0, "kg/(s Pa)"),
            ("Co_cold_bounce", 0.0, "kg/(s Pa^0.5)"),
            ("dP0", 50.0, "Pa"),
            ("Rq_hot_regen", 0.0, "Pa s^2/kg^2"),
        ]
    );
    assert_eq!(
        m.effect_sites(),
        [
            EffectSite {
                effect: "coulomb",
                at: "piston",
                params: &["Fc_piston", "v_eps"]
            },
            EffectSite {
                effect: "end_stops",
                at: "displacer",
                params: &["kc_displacer", "xmax"]
            },
            EffectSite {
                effect: "leak",
                at: "cold -> bounce",
                params: &["Gleak_cold_bounce"]
            },
            EffectSite {
                effect: "orifice_leak",
                at: "cold -> bounce",
                params: &["Co_cold_bounce", "dP0"]
            },
            EffectSite {
                effect: "quadratic",
                at: "link hot -> regen[0]",
                params: &["Rq_hot_regen"]
            },
        ]
    );
}

/// Named where they act or written by hand: one model, with the effects on (the random
/// parameters move every strength off its null) and at their defaults (off).
#[test]
fn an_effect_named_where_it_acts_is_its_hand_written_term() {
    for n in [1, 2, 5] {
        for closure in [Closure::Full, Closure::Frozen] {
            let (named, hand) = (
                Named::new(n, closure).unwrap(),
                Hand::new(n, closure).unwrap(),
            );
            let mut on = named.default_params();
            for (name, v) in [
                ("Fc_piston", 0.8),
                ("kc_displacer", 2e5),
                ("Gleak_cold_bounce", 2e-8),
                ("Co_cold_bounce", 1e-6),
                ("Rq_hot_regen", 1e9),
            ] {
                on[named.param_index(name).unwrap()] = v;
            }
            let w = common::same::same_model(&named, &hand, 7 + n as u64);
            assert!(w < 1e-12, "n = {n} ({closure}): off by {w:e}");
            // with the strengths on, the right-hand sides agree bit for bit
            let x =
                common::random_state(&named, &on, common::Spread::Balanced, &mut common::rng(3));
            let ph: Vec<f64> = hand
                .params()
                .iter()
                .map(|p| on[named.param_index(p.name).unwrap()])
                .collect();
            let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            named.rhs(&on, &x, 0.0, &mut a);
            hand.rhs(&ph, &x, 0.0, &mut b);
            assert_eq!(a, b, "n = {n} ({closure}): effects on");
            let mut off = vec![0.0; x.len()];
            named.rhs(&named.default_params(), &x, 0.0, &mut off);
            assert_ne!(a, off, "n = {n}: the strengths change the model");
        }
    }
}

/// At the null the augmented model is the nominal one, bit for bit (the invariant the
/// diagnosis stands on); and its Jacobians match finite differences with the effects on.
#[test]
fn at_the_null_the_effects_are_absent_and_the_jacobians_hold() {
    for n in [1, 3] {
        let (named, plain) = (
            Named::new(n, Closure::Full).unwrap(),
            Plain::new(n, Closure::Full).unwrap(),
        );
        let p = named.default_params();
        let pp = plain.default_params();
        let x = common::random_state(&plain, &pp, common::Spread::Wide, &mut common::rng(5));
        let (mut a, mut b) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        named.rhs(&p, &x, 0.0, &mut a);
        plain.rhs(&pp, &x, 0.0, &mut b);
        let bits = |v: &[f64]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b), "n = {n}: at the null");
        common::assert_jacobians(&named, &format!("named effects n = {n}"), 43, 3);
    }
}

/// The diagnosis offers the effects the model names, one candidate per effect, with the
/// model's parameter names, and the sensor effects; a library effect the model does not
/// name is refused.
#[test]
fn the_diagnosis_takes_its_candidates_from_the_named_effects() {
    let m = Named::new(2, Closure::Full).unwrap();
    let pool = effects::carried("named", Some(&m));
    let names: Vec<&str> = pool.iter().map(|e| e.name).collect();
    assert_eq!(
        names,
        [
            "coulomb",
            "end_stops",
            "leak",
            "orifice_leak",
            "quadratic",
            "sensor_lag",
            "sensor_gain"
        ]
    );
    let params = |e: &str| -> Vec<(&str, Option<f64>)> {
        let e = pool.iter().find(|x| x.name == e).unwrap();
        e.params.iter().map(|q| (q.name, q.null)).collect()
    };
    assert_eq!(
        params("coulomb"),
        [("Fc_piston", Some(0.0)), ("v_eps", None)]
    );
    assert_eq!(params("leak"), [("Gleak_cold_bounce", Some(0.0))]);
    let typical = |e: &str| {
        pool.iter()
            .find(|x| x.name == e)
            .unwrap()
            .strength()
            .typical
    };
    assert_eq!(typical("quadratic"), 1e9, "the library's regen_quadratic");
    assert_eq!(typical("leak"), 2e-8);
    // the rig sets an effect by its name (its strength) or a parameter
    let set = effects::EffectSettings::parse_for(
        "named",
        Some(&m),
        &["coulomb=0.5".into(), "xmax=0.008".into()],
    )
    .unwrap();
    assert_eq!(
        set.model,
        [("Fc_piston".to_string(), 0.5), ("xmax".to_string(), 0.008)]
    );
    let err =
        effects::EffectSettings::parse_for("named", Some(&m), &["Rq=1e9".into()]).unwrap_err();
    assert!(err.to_string().contains("does not apply"), "{err}");
    let p = effects::nominal_params(&m);
    assert_eq!(p, m.default_params());
}

stirling_model! {
    /// `nsection` with a lag on its hot-side transducer and a gain error on the displacer's
    /// position sensor, named on the sensors.
    pub model Sensed extends stirling::models::nsection_engine {
        name "sensed";
        effect lag on sensor p_hot;
        effect gain on sensor x;
    }
}

/// A lag or gain named on a sensor is listed with its parameter (named after the sensor, not
/// a model parameter: the equations are the nominal ones), carried as a sensor effect, and
/// applied by the rig to that channel alone.
#[test]
fn a_sensor_effect_acts_on_its_sensor_alone() {
    use stirling::models::effects::{EffectSettings, EffectTarget};
    use stirling::models::rig::{measure_with, RigConfig};
    let m = Sensed::new(2, Closure::Full).unwrap();
    assert_eq!(
        m.effect_sites(),
        [
            EffectSite {
                effect: "lag",
                at: "sensor p_hot",
                params: &["tau_p_hot"]
            },
            EffectSite {
                effect: "gain",
                at: "sensor x",
                params: &["gain_x"]
            },
        ]
    );
    let plain = stirling::models::family::NSection::new(2, Closure::Full).unwrap();
    assert_eq!(m.params().len(), plain.params().len());
    let pool = effects::carried("sensed", Some(&m));
    let lag = pool.iter().find(|e| e.name == "lag").unwrap();
    assert_eq!(lag.target, EffectTarget::Sensor);
    assert_eq!((lag.params[0].name, lag.params[0].unit), ("tau_p_hot", "s"));
    assert_eq!(lag.strength().typical, 2e-3, "the library's sensor_lag");
    let set = EffectSettings::parse_for("sensed", Some(&m), &["tau_p_hot=0.004".into()]).unwrap();
    assert_eq!(set.sensor, [("tau_p_hot".to_string(), 0.004)]);
    let err = EffectSettings::parse_for("sensed", Some(&m), &["gain_x=0.7".into()]).unwrap_err();
    assert!(err.to_string().contains("between -0.5 and 0.5"), "{err}");
    let cfg = RigConfig {
        t_end: 0.3,
        channels: ["p", "p_hot", "x", "y"].map(String::from).to_vec(),
        ..Default::default()
    };
    let p = m.default_params();
    let clean = measure_with(&m, &p, &EffectSettings::default(), &cfg).unwrap();
    let lagged = measure_with(&m, &p, &set, &cfg).unwrap();
    assert_eq!(clean.channel("p"), lagged.channel("p"), "p is not lagged");
    let (a, b) = (
        clean.channel("p_hot").unwrap(),
        lagged.channel("p_hot").unwrap(),
    );
    let worst = a
        .iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0, f64::max);
    assert!(worst > 100.0, "p_hot lagged by 4 ms moves by {worst} Pa");
}
