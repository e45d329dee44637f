//! The truth models outside the effect library (`stirling::models::outside`): at their null
//! they are the nominal `nsection`, their analytic Jacobians match central differences, and
//! the rig runs them (`--truth`), with library effects on top when asked.

mod common;

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::outside::{self, OUTSIDE};
use stirling::models::rig::{self, RigConfig};

/// A generic state: rest with the bodies moving (both speeds away from 0).
fn state(m: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    for (i, v) in x.iter_mut().enumerate() {
        *v = match i {
            0 => 3e-3,
            1 => 0.21,
            2 => -2e-3,
            3 => -0.13,
            _ => *v * (1.0 + 0.003 * (i as f64 - 5.0)),
        };
    }
    x
}

#[test]
fn at_their_null_the_outside_models_are_nominal_nsection() {
    for n in [1, 2] {
        let base = NSection::new(n, Closure::Full).unwrap();
        let pb = base.default_params();
        let xb = state(&base, &pb);
        let mut fb = vec![0.0; base.n_states()];
        base.rhs(&pb, &xb, 0.0, &mut fb);
        let jb = base.jacobian_dense(&pb, &xb, 0.0);
        for o in OUTSIDE {
            let m = outside::build(o.name, Some(n), Closure::Full).unwrap();
            assert_eq!(m.state_names(), base.state_names(), "{}", o.name);
            let p = m.default_params();
            assert_eq!(p[m.param_index(o.param).unwrap()], 0.0, "{} null", o.name);
            for bp in base.params() {
                assert_eq!(
                    p[m.param_index(bp.name).unwrap()],
                    bp.default,
                    "{}",
                    bp.name
                );
            }
            let mut f = vec![0.0; m.n_states()];
            m.rhs(&p, &xb, 0.0, &mut f);
            assert_eq!(f, fb, "{} rhs at its null (n = {n})", o.name);
            assert_eq!(
                m.jacobian_dense(&p, &xb, 0.0),
                jb,
                "{} Jacobian at its null",
                o.name
            );
        }
    }
}

#[test]
fn outside_model_jacobians_match_central_differences() {
    for o in OUTSIDE {
        let m = outside::build(o.name, Some(2), Closure::Full).unwrap();
        let mut p = m.default_params();
        p[m.param_index(o.param).unwrap()] = 2.0 * o.typical;
        let x = state(m.as_ref(), &p);
        let bad = common::check_jacobians(m.as_ref(), &p, &x);
        for b in &bad {
            eprintln!(
                "{}: {} / {}: analytic {:e} fd {:e}",
                o.name, b.row, b.col, b.analytic, b.fd
            );
        }
        assert!(bad.is_empty(), "{}: {} mismatches", o.name, bad.len());
    }
}

#[test]
fn the_rig_runs_an_outside_truth_and_it_acts() {
    let cfg = |truth: Option<&str>, set: Vec<String>| RigConfig {
        model: "nsection".into(),
        n: Some(2),
        t_end: 0.5,
        rate: 1000.0,
        noise_p: 0.0,
        noise_x: 0.0,
        truth: truth.map(String::from),
        set,
        ..Default::default()
    };
    let clean = rig::run(&cfg(None, vec![])).unwrap();
    for o in OUTSIDE {
        let on = rig::run(&cfg(
            Some(o.name),
            vec![format!("{}={}", o.param, o.typical)],
        ))
        .unwrap();
        assert_eq!(on.truth.outside.as_deref(), Some(o.name));
        assert_eq!(on.data.channels(), ["p", "x", "y"]);
        let (a, b) = (clean.data.x.as_ref().unwrap(), on.data.x.as_ref().unwrap());
        let diff = a
            .iter()
            .zip(b)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max);
        assert!(diff > 1e-5, "{} changes x by {diff} m only", o.name);
    }
    // a library effect beside the outside cause (the self-check's mixed records): both act
    let alone = rig::run(&cfg(Some("h_speed"), vec!["chv=1".into()])).unwrap();
    let both = rig::run(&RigConfig {
        effects: vec!["Fcd=0.1".into()],
        ..cfg(Some("h_speed"), vec!["chv=1".into()])
    })
    .unwrap();
    assert_eq!(both.truth.outside.as_deref(), Some("h_speed"));
    assert_eq!(both.truth.active_effects, ["coulomb"]);
    assert_eq!(both.truth.parameters["chv"], 1.0);
    let (a, b) = (
        alone.data.x.as_ref().unwrap(),
        both.data.x.as_ref().unwrap(),
    );
    let diff = a
        .iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0, f64::max);
    assert!(diff > 1e-5, "the friction changes x by {diff} m only");
    let err = rig::run(&cfg(Some("bounce"), vec![]))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("unknown truth model `bounce`") && err.contains("h_speed"),
        "{err}"
    );
    let err = rig::run(&RigConfig {
        model: "cv1".into(),
        n: None,
        ..cfg(Some("h_speed"), vec![])
    })
    .unwrap_err()
    .to_string();
    assert!(err.contains("extends nsection"), "{err}");
}
