//! Schmidt's isothermal analysis on the kinematic engines' own volumes (`sim::schmidt`): the
//! gas's entropy returns over a revolution (`sum_i W_i / T_i = 0`), so with two temperatures
//! the work is Carnot's share of the hot space's heat; equal temperatures do no work; the work
//! is linear in the gas mass; bad temperatures, masses and counts are refused by name.

use std::path::Path;

use stirling::dsl::{Closure, Model};
use stirling::models::files;
use stirling::models::sim::schmidt::{schmidt, working_spaces, SchmidtError};

fn engine(name: &str) -> Box<dyn Model> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/engines")
        .join(format!("{name}.stirling"));
    files::build(&path, 1, Closure::Full).expect("the file loads")
}

#[test]
fn the_work_is_carnots_share_of_the_hot_spaces_heat() {
    for name in ["gamma_ltd", "beta", "alpha"] {
        let m = engine(name);
        let p = m.default_params();
        let spaces = working_spaces(m.as_ref());
        assert_eq!(spaces.len(), 2, "{name}: {spaces:?}");
        let (th, tk) = (353.15, 295.15);
        let s = schmidt(m.as_ref(), &p, &[th, tk], 1e-4).unwrap();
        let (wh, wk) = (s.spaces[0].work, s.spaces[1].work);
        eprintln!("{name}: {s:?}");
        assert!(s.work > 0.0, "{name}: the hot space leads: {s:?}");
        // to the volume slopes' differences and the 720-point rule (spectral on the loop)
        let entropy = (wh / th + wk / tk) / (wh.abs() / th);
        eprintln!("{name}: sum W_i/T_i relative {entropy:e}");
        assert!(entropy.abs() < 1e-10, "{name}: {entropy:e}: {s:?}");
        assert!(
            (s.work - wh * (1.0 - tk / th)).abs() < 1e-9 * s.work,
            "{name}: {s:?}"
        );
        assert!(s.p_min < s.p_mean && s.p_mean < s.p_max);
        let flat = schmidt(m.as_ref(), &p, &[tk, tk], 1e-4).unwrap();
        assert!(flat.work.abs() < 1e-11 * wh.abs(), "{name}: {flat:?}");
        let double = schmidt(m.as_ref(), &p, &[th, tk], 2e-4).unwrap();
        assert!(
            (double.work - 2.0 * s.work).abs() < 1e-12 * s.work,
            "{name}"
        );
    }
}

#[test]
fn what_cannot_be_analysed_is_refused_by_name() {
    let m = engine("gamma_ltd");
    let p = m.default_params();
    let e = schmidt(m.as_ref(), &p, &[350.0], 1e-4).unwrap_err();
    assert!(
        matches!(
            e,
            SchmidtError::Temperatures {
                got: 1,
                spaces: 2,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("hot, cold"), "{e}");
    let e = schmidt(m.as_ref(), &p, &[350.0, -1.0], 1e-4).unwrap_err();
    assert!(e.to_string().contains("`cold` is -1 K"), "{e}");
    let e = schmidt(m.as_ref(), &p, &[350.0, 300.0], 0.0).unwrap_err();
    assert!(matches!(e, SchmidtError::Mass(_)), "{e}");
    let (fp, pp) = stirling::models::diagnose::nominal_model("nsection", Some(2)).unwrap();
    let e = schmidt(fp.as_ref(), &pp, &[350.0, 300.0], 1e-4).unwrap_err();
    assert!(e.to_string().contains("has no flywheel"), "{e}");
}
