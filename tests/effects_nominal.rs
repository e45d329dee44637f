//! The augmented models at their effect nulls are the base physics; each effect acts.

use stirling::dsl::{Closure, Model};
use stirling::models::effects::{self, Cv1Fx, EffectSettings, NSectionFx, EFFECTS};
use stirling::models::family::{Cv1, NSection};

/// A generic state: rest perturbed in every entry.
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

/// rhs of the augmented model (its states by name) equals the base model's to `tol` relative
/// (0: bitwise).
fn compare(base: &dyn Model, fx: &dyn Model, tol: f64) {
    let pb = base.default_params();
    let pf = effects::nominal_params(fx);
    assert_eq!(pf, fx.default_params(), "defaults are the nulls");
    for bp in base.params() {
        let i = fx.param_index(bp.name).unwrap();
        assert_eq!(pf[i], bp.default, "{}", bp.name);
    }
    let xb = state(base, &pb);
    let fnames = fx.state_names();
    let bnames = base.state_names();
    let mut xf = state(fx, &pf);
    for (i, n) in bnames.iter().enumerate() {
        let j = fnames.iter().position(|f| f == n).unwrap();
        xf[j] = xb[i];
    }
    // cv1_fx carries the CV mass as a state (the leak link): give it the base's constant mass
    if fnames.len() > bnames.len() {
        let mut eq = vec![0.0; fx.n_states()];
        fx.equilibrium_guess(&pf, &mut eq);
        for (j, n) in fnames.iter().enumerate() {
            if !bnames.contains(n) {
                xf[j] = eq[j];
            }
        }
    }
    let (mut fb, mut ff) = (vec![0.0; base.n_states()], vec![0.0; fx.n_states()]);
    base.rhs(&pb, &xb, 0.0, &mut fb);
    fx.rhs(&pf, &xf, 0.0, &mut ff);
    let mut max_rel = 0.0f64;
    for (i, n) in bnames.iter().enumerate() {
        let j = fnames.iter().position(|f| f == n).unwrap();
        let rel = (fb[i] - ff[j]).abs() / fb[i].abs().max(1e-300);
        max_rel = max_rel.max(rel);
        eprintln!("{:>10} base {:+.17e} fx {:+.17e}", n, fb[i], ff[j]);
        assert!(
            rel <= tol || fb[i] == ff[j],
            "state {n}: {} vs {}",
            fb[i],
            ff[j]
        );
    }
    for (j, n) in fnames.iter().enumerate() {
        if !bnames.contains(n) {
            assert_eq!(ff[j], 0.0, "no leak at the null: {n}' = 0");
        }
    }
    eprintln!("{}: max relative difference {max_rel:e}", fx.name());
}

#[test]
fn nominal_cv1_is_the_base_cv1() {
    // cv1_fx has the CV mass as a state (its leak link) and a differently ordered force sum:
    // equal to a few ulp, not bitwise
    compare(
        &Cv1::new(1, Closure::Full).unwrap(),
        &Cv1Fx::new(1, Closure::Full).unwrap(),
        1e-14,
    );
}

#[test]
fn nominal_nsection_is_the_base_nsection_bitwise() {
    for n in [1, 2, 3] {
        let base = NSection::new(n, Closure::Full).unwrap();
        let fx = NSectionFx::new(n, Closure::Full).unwrap();
        assert_eq!(base.state_names(), fx.state_names());
        let p = base.default_params();
        let pf = fx.default_params();
        let xb = state(&base, &p);
        let (mut fb, mut ff) = (vec![0.0; base.n_states()], vec![0.0; fx.n_states()]);
        base.rhs(&p, &xb, 0.0, &mut fb);
        fx.rhs(&pf, &xb, 0.0, &mut ff);
        assert_eq!(fb, ff, "n = {n}: rhs bitwise equal");
        let jb = base.jacobian_dense(&p, &xb, 0.0);
        let jf = fx.jacobian_dense(&pf, &xb, 0.0);
        let dj = jb
            .iter()
            .zip(&jf)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1e-300))
            .fold(0.0, f64::max);
        assert!(dj < 1e-14, "n = {n}: Jacobian differs by {dj:e}");
    }
    compare(
        &NSection::new(2, Closure::Full).unwrap(),
        &NSectionFx::new(2, Closure::Full).unwrap(),
        0.0,
    );
}

/// Every model effect of `nsection` (those of `nsection_ext` only: tests/effects_ext.rs).
#[test]
fn each_model_effect_changes_the_rhs() {
    let fx = NSectionFx::new(2, Closure::Full).unwrap();
    let p0 = fx.default_params();
    let x = state(&fx, &p0);
    // push x beyond the stops for the end-stop check
    let mut xs = x.clone();
    xs[0] = 0.012;
    let mut f0 = vec![0.0; fx.n_states()];
    for e in EFFECTS
        .iter()
        .filter(|e| e.target == effects::EffectTarget::Model && e.applies_to.contains(&"nsection"))
    {
        let s = EffectSettings::parse(
            "nsection",
            &[format!("{}={}", e.name, e.strength().typical)],
        )
        .unwrap();
        let mut p = p0.clone();
        s.apply(&fx, &mut p).unwrap();
        let xx = if e.name == "end_stops" { &xs } else { &x };
        fx.rhs(&p0, xx, 0.0, &mut f0);
        let mut f1 = vec![0.0; fx.n_states()];
        fx.rhs(&p, xx, 0.0, &mut f1);
        let changed: Vec<String> = fx
            .state_names()
            .into_iter()
            .zip(f0.iter().zip(&f1))
            .filter(|(_, (a, b))| a != b)
            .map(|(n, _)| n)
            .collect();
        eprintln!("{}: changes {changed:?}", e.name);
        assert!(!changed.is_empty(), "{} has no effect", e.name);
    }
}

#[test]
fn registry_maps_names() {
    assert_eq!(
        effects::augmented("cv1", None, Closure::Full)
            .unwrap()
            .name(),
        "cv1_fx"
    );
    assert_eq!(
        effects::augmented("order8", None, Closure::Full)
            .unwrap()
            .n(),
        2
    );
    assert!(effects::augmented("schmidt", None, Closure::Full)
        .err()
        .unwrap()
        .to_string()
        .contains("no augmented member"));
    let e = EffectSettings::parse("cv1", &["regen_quadratic=1e9".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("does not apply to model `cv1`"), "{e}");
    let e = EffectSettings::parse("cv1", &["friction=1".into()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown effect"), "{e}");
    let s = EffectSettings::parse(
        "nsection",
        &[
            "leak=2e-8".into(),
            "xmax=0.004".into(),
            "sensor_lag=1e-3".into(),
        ],
    )
    .unwrap();
    assert_eq!(
        s.model,
        vec![("Gleak".to_string(), 2e-8), ("xmax".to_string(), 0.004)]
    );
    assert_eq!(s.sensor_value("tau_p"), 1e-3);
    assert_eq!(s.active(), vec!["leak", "sensor_lag"]);
}
