//! Mass conservation (docs/physics.md sections 6 and 10): in a closed topology with the `full`
//! closure the mass rows of the right-hand side sum to zero to round-off, and so do the
//! mass rows of the Jacobian (`c J = 0`, the inventory mode).

mod common;

use common::models::{Chain, ChainQuad, TwoCv, TwoCvQuad};
use common::{random_state, Spread};
use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::family::NSection;

/// Indices of the mass states.
fn mass_rows(model: &dyn Model) -> Vec<usize> {
    model
        .states()
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s.kind, StateKind::Mass(_)))
        .map(|(i, _)| i)
        .collect()
}

/// `|sum of terms| <= 4 eps * count * max |term|`, the round-off of the sum of `count` terms.
fn assert_sums_to_zero(terms: &[f64], what: &str) {
    let max = terms.iter().fold(0.0f64, |a, t| a.max(t.abs()));
    let sum: f64 = terms.iter().sum();
    let tol = 4.0 * f64::EPSILON * terms.len() as f64 * max;
    assert!(
        sum.abs() <= tol,
        "{what}: mass rows sum to {sum:e} (largest term {max:e}, tolerance {tol:e})"
    );
}

fn check(model: &dyn Model, label: &str, seed: u64) {
    let rows = mass_rows(model);
    let n = model.n_states();
    assert_eq!(
        rows.len(),
        model.vessel_names().len() - model.topology().vessels.iter().filter(|v| !v.is_cv).count()
    );
    let p = model.default_params();
    let mut rng = common::rng(seed);
    for spread in [Spread::Wide, Spread::Balanced] {
        for k in 0..8 {
            let x = random_state(model, &p, spread, &mut rng);
            let mut f = vec![0.0; n];
            model.rhs(&p, &x, 0.0, &mut f);
            let terms: Vec<f64> = rows.iter().map(|&r| f[r]).collect();
            assert!(
                terms.iter().any(|t| *t != 0.0),
                "{label}: no mass flows at a random state"
            );
            assert_sums_to_zero(&terms, &format!("{label} {spread:?} state {k}, rhs"));
            let jac = model.jacobian_dense(&p, &x, 0.0);
            for c in 0..n {
                let col: Vec<f64> = rows.iter().map(|&r| jac[r + n * c]).collect();
                assert_sums_to_zero(
                    &col,
                    &format!(
                        "{label} {spread:?} state {k}, d/d {}",
                        model.state_names()[c]
                    ),
                );
            }
        }
    }
}

#[test]
fn two_cvs_conserve_mass() {
    check(&TwoCv::new(1, Closure::Full).unwrap(), "two_cv", 11);
    check(
        &TwoCvQuad::new(1, Closure::Full).unwrap(),
        "two_cv_quad",
        12,
    );
}

#[test]
fn chains_conserve_mass() {
    for n in [1, 2, 3, 10, 50] {
        check(
            &Chain::new(n, Closure::Full).unwrap(),
            &format!("chain n={n}"),
            20 + n as u64,
        );
        check(
            &ChainQuad::new(n, Closure::Full).unwrap(),
            &format!("chain_quad n={n}"),
            40 + n as u64,
        );
    }
}

#[test]
fn family_nsection_conserves_mass() {
    for n in [1, 2, 10] {
        check(
            &NSection::new(n, Closure::Full).unwrap(),
            &format!("nsection n={n}"),
            60 + n as u64,
        );
    }
}

/// `gas_mass` is the sum of the mass states (full closure).
#[test]
fn gas_mass_is_the_sum_of_the_mass_states() {
    let model = NSection::new(10, Closure::Full).unwrap();
    let p = model.default_params();
    let x = random_state(&model, &p, Spread::Wide, &mut common::rng(80));
    let sum: f64 = mass_rows(&model).iter().map(|&r| x[r]).sum();
    assert!((model.gas_mass(&p, &x) - sum).abs() <= 1e-14 * sum);
}
