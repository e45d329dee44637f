//! Per-section links (`link r[j] -> bounce for j in 0..n`): every section of an array joined
//! to one space or CV. The scalar end's row holds the sum over the sections (an arrow-shaped
//! Jacobian); checked against finite differences at n = 1, 2, 3, 10, 50, with the energy
//! budget and the mass balance, and linear cost in `n`.

mod common;
#[path = "dsl_sections/models.rs"]
mod models;

use models::{LeakToCv, LeakToSpace};
use stirling::dsl::{Closure, Model, Style};

fn both(n: usize, closure: Closure) -> [Box<dyn Model>; 2] {
    [
        Box::new(LeakToSpace::new(n, closure).unwrap()),
        Box::new(LeakToCv::new(n, closure).unwrap()),
    ]
}

#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 2, 3, 10, 50] {
        for closure in [Closure::Full, Closure::Frozen] {
            let space = LeakToSpace::new(n, closure).unwrap();
            let label = format!("leaktospace n={n} ({closure})");
            common::assert_jacobians(&space, &label, 2000 + 10 * n as u64, 3);
            closed_bounce(n, closure);
        }
    }
}

/// The closed bounce CV's row holds the sum over the sections (the chain-rule Jacobian loop).
/// At wide spreads its regenerator rows reach 5e8 Pa/s, so entries such as `dP_r/dy` are
/// resolved by finite differences only to about 1e-5 (checked by hand against plain central
/// differences at larger steps to 4e-7); at balanced spreads the bounce sits a few Pa from the
/// cold space and `dw'/dAr` is a difference of 1e5 Pa terms (`Spread::Balanced`). So: wide
/// states, relative 2e-5 (a misplaced parenthesis in the sum's chain rule showed as 2.4e-4).
fn closed_bounce(n: usize, closure: Closure) {
    let m = LeakToCv::new(n, closure).unwrap();
    let p = m.default_params();
    let mut rng = common::rng(2500 + 10 * n as u64);
    let mut report = Vec::new();
    for _ in 0..3 {
        let x = common::random_state(&m, &p, common::Spread::Wide, &mut rng);
        for b in common::check_jacobians(&m, &p, &x) {
            let rel = (b.analytic - b.fd).abs() / b.analytic.abs().max(b.fd.abs());
            if rel > 2e-5 {
                report.push(format!(
                    "d {}/d {}: {:e} vs {:e}",
                    b.row, b.col, b.analytic, b.fd
                ));
            }
        }
    }
    assert!(
        report.is_empty(),
        "leaktocv n={n} ({closure}):\n{}",
        report.join("\n")
    );
}

/// The energy budget to round-off (the space's boundary term holds the enthalpy of every
/// section's leak); the gas mass changes only by what leaks into the space.
#[test]
fn energy_and_mass_with_per_section_links() {
    for n in [1, 2, 3, 10, 50] {
        for m in both(n, Closure::Full) {
            let p = m.default_params();
            let mut rng = common::rng(300 + n as u64);
            for _ in 0..4 {
                let x = common::random_state(m.as_ref(), &p, common::Spread::Wide, &mut rng);
                let (de, terms, scale) = common::energy_rate(m.as_ref(), &p, &x);
                let gap = (de - terms).abs() / scale;
                assert!(gap < 1e-14, "{} n={n}: dE/dt {de:e} vs {terms:e}", m.name());
                let (dm, size) = common::mass_rate(m.as_ref(), &p, &x);
                let leak = if m.name() == "leaktospace" {
                    leak_into_space(m.as_ref(), &p, &x)
                } else {
                    0.0
                };
                assert!(
                    (dm + leak).abs() <= 1e-13 * size,
                    "{} n={n}: dm/dt {dm:e}, leak {leak:e}",
                    m.name()
                );
            }
        }
    }
}

/// `sum_j Gl/n (P_j - Pb)` by hand.
fn leak_into_space(m: &dyn Model, p: &[f64], x: &[f64]) -> f64 {
    let v = |name: &str| p[m.param_index(name).unwrap()];
    let n = m.n();
    let names = m.state_names();
    (0..n)
        .map(|j| {
            let i = names
                .iter()
                .position(|s| *s == format!("P_r[{j}]"))
                .unwrap();
            v("Gl") / n as f64 * (x[i] - v("Pb"))
        })
        .sum()
}

/// The scalar end's row depends on every section and every section on it (an arrow): the
/// nonzeros still grow linearly with `n`.
#[test]
fn arrow_jacobian_is_linear_in_n() {
    let nnz = |n: usize| {
        let m = LeakToCv::new(n, Closure::Full).unwrap();
        m.sparsity(&m.default_params()).len()
    };
    let (a, b, c) = (nnz(100), nnz(200), nnz(300));
    eprintln!("nonzeros: {a}, {b}, {c} at n = 100, 200, 300");
    assert_eq!(b - a, c - b);
}

#[test]
fn equations_show_the_sum() {
    let m = LeakToSpace::new(2, Closure::Full).unwrap();
    let text = m.equations(Style::Text);
    let line = text
        .lines()
        .find(|l| l.trim_start().starts_with("S0 ="))
        .expect("a sum");
    eprintln!("{line}");
    assert!(line.contains("sum over j = 0..n-1 of"), "{line}");
}
