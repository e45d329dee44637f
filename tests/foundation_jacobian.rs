//! The generated Jacobian and parameter Jacobian match central finite differences
//! (docs/physics.md section 10) at seeded random states near equilibrium, for small
//! topologies that each exercise one feature, both inventory closures, and chains
//! of n = 1, 2, 3, 10, 50 sections.

mod common;

use common::models::{Chain, ChainQuad, OneCv, TwoCv, TwoCvQuad};
use common::{assert_jacobians, REL};
use stirling::dsl::{Closure, Model};

const STATES: usize = 4;

fn both_closures(make: impl Fn(Closure) -> Box<dyn Model>, label: &str, seed: u64) {
    for closure in [Closure::Full, Closure::Frozen] {
        let model = make(closure);
        assert_jacobians(
            model.as_ref(),
            &format!("{label} ({closure})"),
            seed,
            STATES,
        );
    }
}

#[test]
fn one_cv_one_face_one_port() {
    both_closures(|c| Box::new(OneCv::new(1, c).unwrap()), "one_cv", 1);
}

#[test]
fn two_cvs_linear_link() {
    both_closures(|c| Box::new(TwoCv::new(1, c).unwrap()), "two_cv", 2);
}

#[test]
fn two_cvs_quadratic_link() {
    both_closures(
        |c| Box::new(TwoCvQuad::new(1, c).unwrap()),
        "two_cv_quad",
        3,
    );
}

#[test]
fn chain_linear_links() {
    for n in [1, 2, 3, 10, 50] {
        both_closures(
            |c| Box::new(Chain::new(n, c).unwrap()),
            &format!("chain n={n}"),
            100 + n as u64,
        );
    }
}

#[test]
fn chain_quadratic_links() {
    for n in [1, 2, 3, 10] {
        both_closures(
            |c| Box::new(ChainQuad::new(n, c).unwrap()),
            &format!("chain_quad n={n}"),
            200 + n as u64,
        );
    }
}

#[test]
fn family_nsection() {
    for n in [1, 2, 5] {
        let label = format!("nsection n={n}");
        both_closures(
            |c| Box::new(stirling::models::family::NSection::new(n, c).unwrap()),
            &label,
            300 + n as u64,
        );
    }
}

/// The checker itself: a Jacobian with one wrong entry is caught.
#[test]
fn checker_catches_a_wrong_entry() {
    let model = TwoCv::new(1, Closure::Full).unwrap();
    let p = model.default_params();
    let mut rng = common::rng(7);
    let x = common::random_state(&model, &p, common::Spread::Wide, &mut rng);
    let n = model.n_states();
    let names = model.state_names();
    let scales = common::state_scales(&model, &p);
    let f = |xx: &[f64], out: &mut [f64]| model.rhs(&p, xx, 0.0, out);
    let fd = common::fd_jacobian(&f, &x, n, &common::fd_steps(&model, &p, &x));
    let mut jac = model.jacobian_dense(&p, &x, 0.0);
    assert!(common::compare(
        &jac,
        &fd,
        &names,
        &names,
        &scales,
        &scales,
        REL,
        common::TINY
    )
    .is_empty());
    // perturb the largest entry of the mass column of the hot CV by 1e-5 relative
    let col = names.iter().position(|s| s.starts_with("m_")).unwrap();
    let row = (0..n)
        .max_by(|&a, &b| jac[a + n * col].abs().total_cmp(&jac[b + n * col].abs()))
        .unwrap();
    jac[row + n * col] *= 1.0 + 1e-5;
    assert_eq!(
        common::compare(
            &jac,
            &fd,
            &names,
            &names,
            &scales,
            &scales,
            REL,
            common::TINY
        )
        .len(),
        1
    );
}
