//! The effects on `nsection_ext` (walls with a temperature state and the orifice law):
//! `matrix_capacity` (`km`), `heater_input` (`kh`), `orifice_leak` (`Co`). At their nulls the
//! augmented model with its walls at rest is `nsection` exactly; each effect acts; the
//! Jacobian and parameter Jacobian match central differences with the effects on and off, at
//! n = 1, 2, 3, 10, 50 and seeded random physical states; the registry serves them.

mod common;

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::effects::{self, EffectSettings, NSectionExtFx, NSectionFx};
use stirling::models::family::NSection;

const NEW: [&str; 3] = ["matrix_capacity", "heater_input", "orifice_leak"];
const STARTS: [f64; 4] = [1.0, 10.0, 100.0, 1e3];

/// The parameters of `m` with every new effect at its typical strength.
fn typical(m: &dyn Model) -> Vec<f64> {
    let mut p = effects::nominal_params(m);
    let set: Vec<String> = NEW
        .iter()
        .map(|e| format!("{e}={}", effects::effect(e).unwrap().strength().typical))
        .collect();
    EffectSettings::parse("nsection_ext", &set)
        .unwrap()
        .apply(m, &mut p)
        .unwrap();
    p
}

/// A random state of `ext` whose walls are at rest, and the same state of `base` (by name).
fn states(ext: &dyn Model, base: &dyn Model, seed: u64) -> Vec<(Vec<f64>, Vec<f64>)> {
    let p = ext.default_params();
    let mut rest = vec![0.0; ext.n_states()];
    ext.equilibrium_guess(&p, &mut rest);
    let mut rng = common::rng(seed);
    let names = ext.state_names();
    let mut out = Vec::new();
    for spread in [common::Spread::Wide, common::Spread::Balanced] {
        for _ in 0..2 {
            let mut x = common::random_state(ext, &p, spread, &mut rng);
            for (i, s) in ext.states().iter().enumerate() {
                if matches!(s.kind, StateKind::WallTemperature(_)) {
                    x[i] = rest[i];
                }
            }
            let xb = base
                .state_names()
                .iter()
                .map(|b| x[names.iter().position(|q| q == b).unwrap()])
                .collect();
            out.push((x, xb));
        }
    }
    out
}

/// At the nulls (`km = kh = Co = 0`), walls at rest: the gas and body rows are `nsection`'s
/// and `nsection_fx`'s bitwise, the wall rows are exactly zero.
#[test]
fn nulls_recover_nsection_exactly() {
    for n in [1, 2, 3, 10, 50] {
        let ext = NSectionExtFx::new(n, Closure::Full).unwrap();
        let base = NSection::new(n, Closure::Full).unwrap();
        let fx = NSectionFx::new(n, Closure::Full).unwrap();
        let (pe, pb, pf) = (
            effects::nominal_params(&ext),
            base.default_params(),
            fx.default_params(),
        );
        assert_eq!(pe, ext.default_params(), "the defaults are the nulls");
        assert_eq!(ext.n_states(), base.n_states() + n + 1);
        for (k, (x, xb)) in states(&ext, &base, 17 + n as u64).iter().enumerate() {
            let mut fe = vec![0.0; ext.n_states()];
            ext.rhs(&pe, x, 0.0, &mut fe);
            let (mut fb, mut ff) = (vec![0.0; base.n_states()], vec![0.0; fx.n_states()]);
            base.rhs(&pb, xb, 0.0, &mut fb);
            fx.rhs(&pf, xb, 0.0, &mut ff);
            assert_eq!(
                &fe[..base.n_states()],
                &fb[..],
                "n = {n}, state {k}: nsection"
            );
            assert_eq!(
                &fe[..base.n_states()],
                &ff[..],
                "n = {n}, state {k}: nsection_fx"
            );
            assert!(fe[base.n_states()..].iter().all(|v| *v == 0.0), "wall rows");
        }
    }
}

/// Each new effect at its typical strength changes the right-hand side at a running state.
#[test]
fn each_new_effect_acts() {
    let ext = NSectionExtFx::new(2, Closure::Full).unwrap();
    let base = NSection::new(2, Closure::Full).unwrap();
    let p0 = ext.default_params();
    let (x, _) = states(&ext, &base, 5).remove(0);
    let mut f0 = vec![0.0; ext.n_states()];
    ext.rhs(&p0, &x, 0.0, &mut f0);
    for e in NEW {
        let s = EffectSettings::parse(
            "nsection_ext",
            &[format!(
                "{e}={}",
                effects::effect(e).unwrap().strength().typical
            )],
        )
        .unwrap();
        let mut p = p0.clone();
        s.apply(&ext, &mut p).unwrap();
        let mut f1 = vec![0.0; ext.n_states()];
        ext.rhs(&p, &x, 0.0, &mut f1);
        let changed = f0.iter().zip(&f1).filter(|(a, b)| a != b).count();
        assert!(changed > 0, "{e} has no effect");
        assert_eq!(s.active(), vec![e]);
    }
}

/// Jacobian and parameter Jacobian against Ridders-extrapolated central differences (1e-6),
/// effects at their nulls and at their typical strengths, walls at random temperatures.
#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 2, 3, 10, 50] {
        let m = NSectionExtFx::new(n, Closure::Full).unwrap();
        let mut rng = common::rng(300 + n as u64);
        let mut report = Vec::new();
        for (label, p) in [("nulls", m.default_params()), ("typical", typical(&m))] {
            for spread in [common::Spread::Wide, common::Spread::Balanced] {
                let x = common::random_state(&m, &p, spread, &mut rng);
                for b in common::check_jacobians_from(&m, &p, &x, &STARTS, 0.0) {
                    let rel = (b.analytic - b.fd).abs() / b.analytic.abs().max(b.fd.abs());
                    // the chains' switches at n = 50, as in tests/dsl_sections.rs
                    let tol = if n >= 50 && b.col == "param mdot_eps" {
                        1e-5
                    } else {
                        common::REL
                    };
                    if rel > tol {
                        report.push(format!(
                            "n={n} {label} {spread:?}: d {}/d {}: {:e} vs {:e} ({rel:.1e})",
                            b.row, b.col, b.analytic, b.fd
                        ));
                    }
                }
            }
        }
        assert!(report.is_empty(), "{}", report.join("\n"));
    }
}

/// The registry: `nsection_ext` has an augmented member; the new effects apply to it only,
/// and the default candidates of `cv1` and `nsection` are unchanged.
#[test]
fn registry_serves_the_new_effects() {
    let m = effects::augmented("nsection_ext", Some(3), Closure::Full).unwrap();
    assert_eq!((m.name(), m.n()), ("nsection_ext_fx", 3));
    let names = |b: &str| -> Vec<&str> { effects::effects_for(b).iter().map(|e| e.name).collect() };
    let old = [
        "leak",
        "coulomb",
        "regen_quadratic",
        "end_stops",
        "sensor_lag",
        "sensor_gain",
    ];
    assert_eq!(names("nsection"), old.to_vec());
    assert_eq!(
        names("cv1"),
        ["leak", "coulomb", "end_stops", "sensor_lag", "sensor_gain"]
    );
    let ext = names("nsection_ext");
    assert!(old.iter().chain(&NEW).all(|e| ext.contains(e)), "{ext:?}");
    let e = EffectSettings::parse("nsection", &["matrix_capacity=2".into()]).unwrap_err();
    assert!(e.to_string().contains("it applies to nsection_ext"), "{e}");
    let s = EffectSettings::parse(
        "nsection_ext",
        &["km=0.02".into(), "Gloss=1".into(), "Co=1e-6".into()],
    );
    assert_eq!(s.unwrap().active(), vec!["matrix_capacity", "orifice_leak"]);
    let e = EffectSettings::parse("nsection_ext", &["Gm=0".into()]).unwrap_err();
    assert!(e.to_string().contains("must be > 0"), "{e}");
    assert!(effects::augmented("nsection_ext", Some(0), Closure::Full).is_err());
}
