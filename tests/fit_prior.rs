//! The log-normal prior rows of the fit: values, analytic derivatives against finite
//! differences (also below the floor where the logarithm continues linearly), and which
//! variables carry one.

use stirling::models::fit::prior::{prior_count, prior_rows};
use stirling::models::fit::vars::{Var, VarKind};

fn var(initial: f64, scale: f64, prior: Option<f64>) -> Var {
    Var {
        name: "q".into(),
        initial,
        scale,
        kind: VarKind::Param(0),
        prior,
        bounds: None,
    }
}

#[test]
fn prior_residual_is_the_log_ratio_in_standard_deviations() {
    let vars = [var(500.0, 500.0, Some(0.5))];
    // value 500 (1 + u) = 250: ln(0.5) / 0.5
    let rows = prior_rows(&vars, &[-0.5]);
    assert_eq!(rows.len(), 1);
    assert!((rows[0].r - 0.5f64.ln() / 0.5).abs() < 1e-12, "{rows:?}");
}

#[test]
fn prior_derivatives_match_finite_differences() {
    let vars = [
        var(500.0, 500.0, Some(0.5)),
        var(-2.0, 0.1, Some(0.3)),
        var(7.9, 7.9, Some(1.0)),
    ];
    // second point: below the floor for the first variable (ratio 0.02)
    for u in [[0.3, -1.0, 0.2], [-0.98, 4.0, -0.5]] {
        let rows = prior_rows(&vars, &u);
        assert_eq!(rows.len(), 3);
        for row in &rows {
            let h = 1e-6;
            let mut up = u;
            let mut dn = u;
            up[row.var] += h;
            dn[row.var] -= h;
            let fd =
                (prior_rows(&vars, &up)[row.var].r - prior_rows(&vars, &dn)[row.var].r) / (2.0 * h);
            assert!(
                (fd - row.dr_du).abs() < 1e-6 * (1.0 + fd.abs()),
                "var {}: fd {fd}, analytic {}",
                row.var,
                row.dr_du
            );
        }
    }
}

#[test]
fn only_nonzero_variables_with_a_prior_carry_a_row() {
    let vars = [
        var(500.0, 500.0, None),
        var(0.0, 1.0, Some(0.5)),
        var(3.0, 3.0, Some(0.0)),
        var(3.0, 3.0, Some(0.2)),
    ];
    let rows = prior_rows(&vars, &[0.1, 0.1, 0.1, 0.1]);
    assert_eq!(prior_count(&vars), 1);
    assert_eq!(rows.len(), 1);
    assert_eq!(rows[0].var, 3);
}
