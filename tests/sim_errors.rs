//! Nonphysical parameter sets and runs driven out of the physical range give
//! clear errors (time and quantity), never panics.

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::params;
use stirling::models::sim::{self, SimError, SimOptions};

fn model() -> NSection {
    NSection::new(2, Closure::Full).unwrap()
}

#[test]
fn nonphysical_parameter_sets_are_rejected_by_name() {
    let m = model();
    for set in ["Th=200", "Vh0=-1e-4", "gamma=0.9", "md=0"] {
        let e = params::load(&m, None, &[set.to_string()]).unwrap_err();
        eprintln!("--set {set}: {e}");
        assert!(e.to_string().contains(set.split('=').next().unwrap()));
    }
}

#[test]
fn an_unphysical_parameter_vector_stops_at_t_zero() {
    let m = model();
    let mut p = m.default_params();
    p[m.param_index("Vh0").unwrap()] = -1e-5;
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    let e = sim::simulate(&m, &p, &x0, 0.1, &[], &SimOptions::default()).unwrap_err();
    eprintln!("{e}");
    assert!(
        matches!(e, SimError::Nonphysical { t, .. } if t == 0.0),
        "{e:?}"
    );
}

#[test]
fn a_run_driven_to_negative_volume_names_time_and_quantity() {
    // tiny hot space at rest: the displacer's stroke crushes it
    let m = model();
    let p = params::load(&m, None, &["Vh0=2e-6".to_string()]).unwrap();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[1] = 2.0; // displacer velocity toward the hot end
    let e = sim::simulate(&m, &p, &x0, 0.1, &[], &SimOptions::default()).unwrap_err();
    eprintln!("{e}");
    let msg = e.to_string();
    assert!(msg.contains("t = "), "{msg}");
    match e {
        SimError::Nonphysical { t, quantity, .. } => {
            assert!(t > 0.0 && t < 0.1);
            assert!(
                quantity.contains("hot")
                    || quantity.contains("temperature")
                    || quantity.contains("pressure"),
                "{quantity}"
            );
        }
        SimError::StepSizeCollapse { t } | SimError::SolverFailure { t, .. } => assert!(t > 0.0),
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn a_huge_initial_displacement_is_rejected() {
    let m = model();
    let p = m.default_params();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[0] = 0.1; // 10 cm: the hot space would be negative
    let e = sim::simulate(&m, &p, &x0, 0.1, &[], &SimOptions::default()).unwrap_err();
    eprintln!("{e}");
    assert!(e.to_string().contains("volume of `hot"), "{e}");
}

#[test]
fn a_wrong_state_length_is_an_error() {
    let m = model();
    let p = m.default_params();
    let e = sim::simulate(&m, &p, &[0.0; 3], 0.1, &[], &SimOptions::default()).unwrap_err();
    assert!(matches!(e, SimError::DimensionMismatch { .. }));
}
