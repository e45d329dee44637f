//! The equilibrium of docs/physics.md section 6 and the analytic Jacobian (section 10):
//! the right-hand side vanishes at `equilibrium_guess` for every member and closure,
//! and the generated Jacobian matches central finite differences, at rest and away from it.

use stirling::dsl::{Closure, Model, StateKind};
use stirling::models::build;

const SECTIONS: [usize; 4] = [1, 2, 3, 10];

/// Every member at every tested `n` and closure.
fn family() -> Vec<Box<dyn Model>> {
    let mut out = Vec::new();
    for closure in [Closure::Full, Closure::Frozen] {
        for name in ["schmidt", "cv1", "cv2"] {
            out.push(build(name, None, closure).unwrap());
        }
        for n in SECTIONS {
            out.push(build("nsection", Some(n), closure).unwrap());
        }
    }
    out
}

fn label(m: &dyn Model) -> String {
    format!("{} n={} {}", m.name(), m.n(), m.closure())
}

fn equilibrium(m: &dyn Model, p: &[f64]) -> Vec<f64> {
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(p, &mut x);
    x
}

fn rhs(m: &dyn Model, p: &[f64], x: &[f64]) -> Vec<f64> {
    let mut f = vec![0.0; m.n_states()];
    m.rhs(p, x, 0.0, &mut f);
    f
}

/// A typical size of each state's excursion: 1 mm, 0.1 m/s, 1 % of the charge pressure and of the mass.
fn typical(m: &dyn Model, p: &[f64], eq: &[f64]) -> Vec<f64> {
    let pmean = p[m.param_index("Pmean").unwrap()];
    m.states()
        .iter()
        .zip(eq)
        .map(|(s, &e)| match s.kind {
            StateKind::Position(_) => 1e-3,
            StateKind::Velocity(_) => 0.1,
            StateKind::Pressure(_) => 0.01 * pmean,
            StateKind::Mass(_) => 0.01 * e,
            StateKind::WallTemperature(_) => 1.0,
        })
        .collect()
}

/// The test state of the reference check: equilibrium plus x = +3 mm, v = 0.2 m/s, y = -2 mm,
/// w = -0.1 m/s, `P_i = Pmean (1 + 0.01 (i+1))`, `m_i = 1.02 m_i0 (1 - 0.005 i)`.
fn off_equilibrium(m: &dyn Model, p: &[f64]) -> Vec<f64> {
    let pmean = p[m.param_index("Pmean").unwrap()];
    let mut x = equilibrium(m, p);
    for (s, xi) in m.states().iter().zip(x.iter_mut()) {
        match s.kind {
            StateKind::Position(0) => *xi += 0.003,
            StateKind::Velocity(0) => *xi += 0.2,
            StateKind::Position(_) => *xi += -0.002,
            StateKind::Velocity(_) => *xi += -0.1,
            StateKind::Pressure(i) => *xi = pmean * (1.0 + 0.01 * (i + 1) as f64),
            StateKind::Mass(i) => *xi *= 1.02 * (1.0 - 0.005 * i as f64),
            StateKind::WallTemperature(_) => *xi += 1.0,
        }
    }
    x
}

/// Row scales: how much each derivative moves for a typical excursion of every state
/// (`sum_c |J_rc| s_c`), the size of the terms the row is made of near rest.
fn row_scales(m: &dyn Model, p: &[f64], x: &[f64], s: &[f64]) -> Vec<f64> {
    let n = m.n_states();
    let j = m.jacobian_dense(p, x, 0.0);
    (0..n)
        .map(|r| (0..n).map(|c| (j[r + n * c] * s[c]).abs()).sum())
        .collect()
}

#[test]
fn rhs_vanishes_at_the_equilibrium() {
    for m in family() {
        let m = m.as_ref();
        let p = m.default_params();
        let eq = equilibrium(m, &p);
        let f = rhs(m, &p, &eq);
        let scale = row_scales(m, &p, &eq, &typical(m, &p, &eq));
        for (r, (fr, sr)) in f.iter().zip(&scale).enumerate() {
            assert!(
                fr.abs() <= 1e-12 * sr,
                "{}: row {r} ({}) = {fr:e}, scale {sr:e}",
                label(m),
                m.state_names()[r]
            );
        }
    }
}

#[test]
fn equilibrium_is_at_rest_at_the_charge_pressure() {
    for m in family() {
        let m = m.as_ref();
        let p = m.default_params();
        let pmean = p[m.param_index("Pmean").unwrap()];
        let eq = equilibrium(m, &p);
        for (s, v) in m.states().iter().zip(&eq) {
            match s.kind {
                StateKind::Position(_) | StateKind::Velocity(_) => {
                    assert_eq!(*v, 0.0, "{} {}", label(m), s.name)
                }
                StateKind::Pressure(_) => assert_eq!(*v, pmean, "{} {}", label(m), s.name),
                StateKind::Mass(_) | StateKind::WallTemperature(_) => {
                    assert!(*v > 0.0, "{} {}", label(m), s.name)
                }
            }
        }
    }
}

#[test]
fn rhs_vanishes_at_equilibrium_of_other_parameters() {
    let sets: [&[(&str, f64)]; 3] = [
        &[("Th", 750.0), ("Tk", 320.0)],
        &[("Pmean", 2.0e6), ("Pb", 2.0e6)],
        &[("Rf", 3.0e3), ("hr", 4e3)],
    ];
    for m in family() {
        let m = m.as_ref();
        for set in sets {
            let mut p = m.default_params();
            for (k, v) in set {
                p[m.param_index(k).unwrap()] = *v;
            }
            let eq = equilibrium(m, &p);
            let f = rhs(m, &p, &eq);
            let scale = row_scales(m, &p, &eq, &typical(m, &p, &eq));
            for (r, (fr, sr)) in f.iter().zip(&scale).enumerate() {
                assert!(
                    fr.abs() <= 1e-12 * sr,
                    "{} {set:?}: row {r} = {fr:e}, scale {sr:e}",
                    label(m)
                );
            }
        }
    }
}

/// Central-difference step per state. The upwind switch `tanh(mdot/mdot_eps)` has a pressure
/// width `mdot_eps Rlink` (0.5/n Pa at defaults): pressure steps must resolve it.
fn step(m: &dyn Model, x: &[f64]) -> Vec<f64> {
    m.states()
        .iter()
        .zip(x)
        .map(|(s, &v)| match s.kind {
            StateKind::Position(_) => 1e-7,
            StateKind::Velocity(_) => 1e-6,
            StateKind::Pressure(_) => 1e-4,
            StateKind::Mass(_) => 1e-7 * v.abs(),
            StateKind::WallTemperature(_) => 1e-4,
        })
        .collect()
}

fn central_differences(m: &dyn Model, p: &[f64], x: &[f64]) -> Vec<f64> {
    let n = m.n_states();
    let h = step(m, x);
    let mut fd = vec![0.0; n * n];
    for c in 0..n {
        let (mut xp, mut xm) = (x.to_vec(), x.to_vec());
        xp[c] += h[c];
        xm[c] -= h[c];
        let (fp, fm) = (rhs(m, p, &xp), rhs(m, p, &xm));
        for r in 0..n {
            fd[r + n * c] = (fp[r] - fm[r]) / (2.0 * h[c]);
        }
    }
    fd
}

/// `|J - FD| s_c <= 1e-6 (row scale) + 1e-5 |J s_c|` entry by entry, columns scaled by the
/// typical excursion so that rows mixing units (m, m/s, Pa, kg) compare fairly.
fn assert_jacobian_matches(m: &dyn Model, p: &[f64], x: &[f64], at: &str) {
    let n = m.n_states();
    let j = m.jacobian_dense(p, x, 0.0);
    let fd = central_differences(m, p, x);
    let s = typical(m, p, &equilibrium(m, p));
    let scale = row_scales(m, p, x, &s);
    let names = m.state_names();
    for r in 0..n {
        for c in 0..n {
            let (a, b) = (j[r + n * c] * s[c], fd[r + n * c] * s[c]);
            let tol = 1e-6 * scale[r] + 1e-5 * a.abs();
            assert!(
                (a - b).abs() <= tol,
                "{} at {at}: d {}'/d {}: analytic {:e}, finite differences {:e}",
                label(m),
                names[r],
                names[c],
                j[r + n * c],
                fd[r + n * c]
            );
        }
    }
}

#[test]
fn jacobian_matches_finite_differences_at_equilibrium() {
    for m in family() {
        let p = m.default_params();
        let eq = equilibrium(m.as_ref(), &p);
        assert_jacobian_matches(m.as_ref(), &p, &eq, "equilibrium");
    }
}

#[test]
fn jacobian_matches_finite_differences_off_equilibrium() {
    for m in family() {
        let p = m.default_params();
        let x = off_equilibrium(m.as_ref(), &p);
        assert_jacobian_matches(m.as_ref(), &p, &x, "the test state");
    }
}

/// Near `mdot = 0` the upwind switch is in its smooth band: a link pressure difference of a
/// fraction of `mdot_eps Rlink` tests the tanh derivative itself.
#[test]
fn jacobian_matches_finite_differences_inside_the_upwind_band() {
    for m in family() {
        let m = m.as_ref();
        let p = m.default_params();
        let mut x = equilibrium(m, &p);
        for (s, xi) in m.states().iter().zip(x.iter_mut()) {
            match s.kind {
                StateKind::Pressure(i) => *xi += 0.05 / m.n() as f64 * (i as f64 - 0.7),
                StateKind::Position(_) => *xi += 1e-3,
                StateKind::Velocity(_) => *xi += -0.05,
                _ => {}
            }
        }
        assert_jacobian_matches(m, &p, &x, "a state inside the upwind band");
    }
}

#[test]
fn full_closure_conserves_mass_and_its_jacobian_has_the_inventory_mode() {
    for m in family()
        .into_iter()
        .filter(|m| m.closure() == Closure::Full)
    {
        let m = m.as_ref();
        let p = m.default_params();
        let x = off_equilibrium(m, &p);
        let f = rhs(m, &p, &x);
        let masses: Vec<usize> = m
            .states()
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.kind, StateKind::Mass(_)))
            .map(|(k, _)| k)
            .collect();
        let mdot: f64 = masses.iter().map(|&k| f[k]).sum();
        let flow: f64 = masses.iter().map(|&k| f[k].abs()).sum();
        assert!(
            mdot.abs() <= 1e-13 * flow.max(1e-30),
            "{}: sum m' = {mdot:e}",
            label(m)
        );
        let n = m.n_states();
        let j = m.jacobian_dense(&p, &x, 0.0);
        for c in 0..n {
            let cj: f64 = masses.iter().map(|&r| j[r + n * c]).sum();
            let size: f64 = masses.iter().map(|&r| j[r + n * c].abs()).sum();
            assert!(
                cj.abs() <= 1e-13 * size.max(1e-30),
                "{}: (c J) column {c} = {cj:e}",
                label(m)
            );
        }
    }
}
