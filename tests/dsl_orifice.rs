//! Orifice links (`link a -> b { orifice: C, dp0: dP0 }`): the square-root law regularized near
//! zero, `mdot = C dP / (dP^2 + dP0^2)^(1/4)`. Its Jacobian against finite differences at
//! n = 1, 2, 3, 10, 50, at wide and balanced random states and at states whose orifice pressure
//! difference is 1e-3 dP0, dP0 and 100 dP0 (both signs); the law itself at both ends; energy
//! and mass; the printed equation.

mod common;
#[path = "dsl_sections/models.rs"]
mod models;

use models::{OrificeToCv, OrificeToSpace};
use stirling::dsl::{Closure, Model, Style};

const STARTS: [f64; 5] = [1.0, 10.0, 100.0, 1e3, 1e4];

fn idx(m: &dyn Model, name: &str) -> usize {
    m.state_names().iter().position(|q| q == name).unwrap()
}

fn par(m: &dyn Model, p: &[f64], name: &str) -> f64 {
    p[m.param_index(name).unwrap()]
}

/// `d mdot / d dP` of the regularized law: `C (dP^2/2 + dP0^2) / (dP^2 + dP0^2)^(5/4)`.
fn slope(c: f64, dp0: f64, dp: f64) -> f64 {
    c * (0.5 * dp * dp + dp0 * dp0) / (dp * dp + dp0 * dp0).powf(1.25)
}

/// The states to check: wide and balanced random ones, and ones whose orifice pressure
/// differences are `k dP0` for `k` in +-1e-3, +-1, +-100.
fn states(m: &dyn Model, seed: u64) -> Vec<(String, Vec<f64>)> {
    let p = m.default_params();
    let mut rng = common::rng(seed);
    let mut out = Vec::new();
    for spread in [common::Spread::Wide, common::Spread::Balanced] {
        for k in 0..2 {
            let x = common::random_state(m, &p, spread, &mut rng);
            out.push((format!("{spread:?} {k}"), x));
        }
    }
    let dp0 = par(m, &p, "dP0");
    for k in [1e-3, -1e-3, 1.0, -1.0, 100.0, -100.0] {
        let mut x = common::random_state(m, &p, common::Spread::Wide, &mut rng);
        if m.name() == "orificetospace" {
            x[idx(m, "P_cold")] = par(m, &p, "Pb") + k * dp0;
        } else {
            // section 0 k dP0 above the bounce (the others at their random pressures: sections
            // closer to each other than the chains' upwind switches resolve would bind the
            // finite-difference steps to 1e-5 Pa, below the round-off of the bounce's row)
            let pb = x[idx(m, "P_bounce")];
            x[idx(m, "P_r[0]")] = pb + k * dp0;
        }
        out.push((format!("dP = {k:e} dP0"), x));
    }
    out
}

/// FD check of both Jacobians to 1e-6 (returns the worst relative error); the sections' entries
/// in the closed bounce's pressure and mass columns are below FD resolution (see
/// tests/dsl_sections.rs) and are checked by hand in [`orifice_arrow_entries_by_hand`].
fn fd_check(m: &dyn Model, seed: u64) -> f64 {
    let p = m.default_params();
    let mut report = Vec::new();
    let mut worst = 0.0f64;
    for (label, x) in states(m, seed) {
        let w = common::arrow_fd_errors(m, &p, &x, &STARTS, &label, &mut report);
        worst = worst.max(w);
    }
    assert!(
        report.is_empty(),
        "{} n={} {:?}:\n{}",
        m.name(),
        m.n(),
        m.closure(),
        report.join("\n")
    );
    worst
}

#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 2, 3, 10, 50] {
        for closure in [Closure::Full, Closure::Frozen] {
            let w1 = fd_check(&OrificeToSpace::new(n, closure).unwrap(), 4000 + n as u64);
            let w2 = fd_check(&OrificeToCv::new(n, closure).unwrap(), 4500 + n as u64);
            eprintln!(
                "n={n} ({closure}): max relative FD error, space {w1:.2e}, per-section CV {w2:.2e}"
            );
        }
    }
}

/// The arrow's orifice entries: `dm_j'/dP_b = dm_b'/dP_j = slope(C/n, dP0, P_j - P_b)`.
#[test]
fn orifice_arrow_entries_by_hand() {
    let mut worst = 0.0f64;
    for n in [1, 2, 3, 10, 50] {
        let m = OrificeToCv::new(n, Closure::Full).unwrap();
        let p = m.default_params();
        let ns = m.n_states();
        let (c, dp0) = (par(&m, &p, "Co") / n as f64, par(&m, &p, "dP0"));
        for (label, x) in states(&m, 4700 + n as u64) {
            let jac = m.jacobian_dense(&p, &x, 0.0);
            let pb = x[idx(&m, "P_bounce")];
            for j in 0..n {
                let pj = idx(&m, &format!("P_r[{j}]"));
                let want = slope(c, dp0, x[pj] - pb);
                let a = jac[idx(&m, &format!("m_r[{j}]")) + ns * idx(&m, "P_bounce")];
                let b = jac[idx(&m, "m_bounce") + ns * pj];
                for got in [a, b] {
                    let e = (got - want).abs() / want;
                    worst = worst.max(e);
                    assert!(e < 1e-13, "n={n} {label} j={j}: {got:e} vs {want:e}");
                }
            }
        }
    }
    eprintln!("orifice arrow entries vs hand: max relative difference {worst:.1e}");
}

/// The law: `C dP / sqrt(dP0)` below `dP0`, `C sign(dP) sqrt|dP|` far above it (to the relative
/// `(dP0/dP)^2/4` of the regularization), read from the gas mass rate of the space model (the
/// gas loses exactly what flows through the orifice).
#[test]
fn square_root_law_far_out_linear_inside() {
    let m = OrificeToSpace::new(3, Closure::Full).unwrap();
    let p = m.default_params();
    let (c, dp0, pb) = (par(&m, &p, "Co"), par(&m, &p, "dP0"), par(&m, &p, "Pb"));
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    for k in [1e-2, 1e-3, -1e-3, 1.0, 1e2, 1e4, -1e4] {
        x[idx(&m, "P_cold")] = pb + k * dp0;
        // the difference the model sees (pb + k dP0 is rounded to the ulp of 1e5 Pa)
        let dp = x[idx(&m, "P_cold")] - pb;
        let (dm, size) = common::mass_rate(&m, &p, &x);
        let mdot = -dm;
        let root = c * dp.signum() * dp.abs().sqrt();
        let linear = c * dp / dp0.sqrt();
        let exact = c * dp / (dp * dp + dp0 * dp0).powf(0.25);
        // to the round-off of the mass sum (the chain flow into the cold CV cancels in it)
        let tol = 1e-14 * exact.abs() + 4.0 * f64::EPSILON * size;
        assert!((mdot - exact).abs() <= tol, "k={k}: {mdot:e} vs {exact:e}");
        let (to_root, to_linear) = ((mdot / root - 1.0).abs(), (mdot / linear - 1.0).abs());
        eprintln!("dP = {k:e} dP0: mdot {mdot:.6e}; /sqrt law - 1 = {to_root:.2e}, /linear - 1 = {to_linear:.2e}");
        if k.abs() >= 1e2 {
            // the regularization's relative effect, (dP0/dP)^2 / 4 to first order
            let want = 0.25 / (k * k);
            let noise = tol / mdot.abs(); // the mass sum's round-off, relative
            assert!(
                (to_root - want).abs() <= 1e-3 * want + noise,
                "k={k}: {to_root:e} vs {want:e} (+- {noise:.1e})"
            );
        }
        if k.abs() <= 1e-2 {
            let want = 0.25 * k * k; // 1 - (1 + k^2)^(-1/4)
            let noise = tol / mdot.abs();
            assert!(
                (to_linear - want).abs() <= 1e-3 * want + noise,
                "k={k}: {to_linear:e} vs {want:e} (+- {noise:.1e})"
            );
        }
    }
}

#[test]
fn energy_and_mass_with_orifices() {
    let (mut worst, mut worst_mass) = (0.0f64, 0.0f64);
    for n in [1, 2, 3, 10, 50] {
        let models: [Box<dyn Model>; 2] = [
            Box::new(OrificeToSpace::new(n, Closure::Full).unwrap()),
            Box::new(OrificeToCv::new(n, Closure::Full).unwrap()),
        ];
        for m in models {
            let p = m.default_params();
            for (label, x) in states(m.as_ref(), 4900 + n as u64) {
                let (de, terms, scale) = common::energy_rate(m.as_ref(), &p, &x);
                let gap = (de - terms).abs() / scale;
                worst = worst.max(gap);
                assert!(
                    gap < 1e-15,
                    "{} n={n} {label}: dE/dt {de:e} vs {terms:e}",
                    m.name()
                );
                let (dm, size) = common::mass_rate(m.as_ref(), &p, &x);
                let leak = if m.name() == "orificetospace" {
                    let (c, dp0) = (par(m.as_ref(), &p, "Co"), par(m.as_ref(), &p, "dP0"));
                    let dp = x[idx(m.as_ref(), "P_cold")] - par(m.as_ref(), &p, "Pb");
                    c * dp / (dp * dp + dp0 * dp0).powf(0.25)
                } else {
                    0.0
                };
                worst_mass = worst_mass.max((dm + leak).abs() / size);
                assert!(
                    (dm + leak).abs() <= 1e-13 * size,
                    "{} n={n} {label}: dm/dt {dm:e}, leak {leak:e}",
                    m.name()
                );
            }
        }
    }
    eprintln!("energy: max |dE/dt - terms| = {worst:.1e} of the round-off scale; mass: {worst_mass:.1e} of sum |m'|");
}

/// The printed orifice equations (review them): the scalar orifice of the space model and the
/// per-section one of the closed CV model.
#[test]
fn orifice_equations_text() {
    let pick = |text: String| -> String {
        text.lines()
            .filter(|l| l.contains("_bounce =") || l.contains("S1 ="))
            .map(|l| l.trim().to_string())
            .collect::<Vec<_>>()
            .join("\n")
    };
    let a = pick(
        OrificeToSpace::new(2, Closure::Full)
            .unwrap()
            .equations(Style::Text),
    );
    let b = pick(
        OrificeToCv::new(2, Closure::Full)
            .unwrap()
            .equations(Style::Text),
    );
    insta::assert_snapshot!("orifice_equations", format!("{a}\n\n{b}"));
}
