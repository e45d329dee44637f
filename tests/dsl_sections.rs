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
            let w1 = fd_check(&space, 2000 + 10 * n as u64);
            let cv = LeakToCv::new(n, closure).unwrap();
            let w2 = fd_check(&cv, 2500 + 10 * n as u64);
            eprintln!(
                "n={n} ({closure}): max relative FD error, space {w1:.2e}, closed CV {w2:.2e}"
            );
        }
    }
}

/// Upper steps of the finite differences of the per-section models: the default steps and 10
/// to 1e4 times larger (pressures capped by their gaps to the pressures they are linked to).
const STARTS: [f64; 5] = [1.0, 10.0, 100.0, 1e3, 1e4];

/// The closed bounce CV's rows hold the sum over the sections (the chain-rule Jacobian loops,
/// an arrow). At wide spreads a regenerator row reaches `|P'| ~ 5e8 Pa/s` (n = 1) to 5e11
/// (n = 50) while its leak entries are small: `dP_j'/dx` (the bounce temperature in the leak's
/// upwind enthalpy) ~ 300 Pa/(s m), `dm_j'/dP_b = 1/(Rl n)` = 2e-10 kg/(s Pa) at n = 50. A
/// central difference at the default steps (1e-5 m, 1e-3 Pa) carries a round-off of
/// `eps |f_i| / h`, 4e-5 of `dP_j'/dx` at n = 1 and 3e-3 of `dm_j'/dP_b` at n = 50: the
/// disagreements of the first version of this test. Larger upper steps (`STARTS`) resolve
/// every entry to 1e-6 except the sections' entries in the bounce pressure's and mass's
/// columns (the pressure's steps are capped by the gap between the bounce and the nearest
/// section, 5 %; `dP_j'/dm_b` is 1e-5 of a row of 5e11 Pa/s at n = 50): those are
/// checked exactly against a hand derivation instead ([`leak_entries_match_hand_derivation`],
/// to 1e-13 at n = 1..50, the arrow's entries included).
fn fd_check(m: &dyn Model, seed: u64) -> f64 {
    let p = m.default_params();
    let mut rng = common::rng(seed);
    let mut report = Vec::new();
    let mut worst = 0.0f64;
    for spread in [common::Spread::Wide, common::Spread::Balanced] {
        for k in 0..3 {
            let x = common::random_state(m, &p, spread, &mut rng);
            let label = format!("{spread:?} {k}");
            let w = common::arrow_fd_errors(m, &p, &x, &STARTS, &label, &mut report);
            worst = worst.max(w);
        }
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

/// The energy budget to round-off (the space's boundary term holds the enthalpy of every
/// section's leak); the gas mass changes only by what leaks into the space.
#[test]
fn energy_and_mass_with_per_section_links() {
    let (mut worst, mut worst_mass) = (0.0f64, 0.0f64);
    for n in [1, 2, 3, 10, 50] {
        for m in both(n, Closure::Full) {
            let p = m.default_params();
            let mut rng = common::rng(300 + n as u64);
            for _ in 0..4 {
                let x = common::random_state(m.as_ref(), &p, common::Spread::Wide, &mut rng);
                let (de, terms, scale) = common::energy_rate(m.as_ref(), &p, &x);
                let gap = (de - terms).abs() / scale;
                worst = worst.max(gap);
                assert!(gap < 1e-15, "{} n={n}: dE/dt {de:e} vs {terms:e}", m.name());
                let (dm, size) = common::mass_rate(m.as_ref(), &p, &x);
                let leak = if m.name() == "leaktospace" {
                    leak_into_space(m.as_ref(), &p, &x)
                } else {
                    0.0
                };
                worst_mass = worst_mass.max((dm + leak).abs() / size);
                assert!(
                    (dm + leak).abs() <= 1e-13 * size,
                    "{} n={n}: dm/dt {dm:e}, leak {leak:e}",
                    m.name()
                );
            }
        }
    }
    eprintln!("energy: max |dE/dt - terms| = {worst:.1e} of the round-off scale; mass: max |sum m' + leak| = {worst_mass:.1e} of sum |m'|");
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

/// The leak entries of the closed bounce CV derived by hand (full closure): the regenerator
/// rows' columns of the bounce (`P_b`, `x`, `y`) and the bounce rows' columns of the sections
/// (the arrow), from `mdot_j = (P_j - P_b)/(Rl n)` and `H_j = cp mdot_j (T_b + s_j (T_j -
/// T_b))`, `s_j = (1 + tanh(mdot_j/eps))/2`, `T = P V/(m R)`.
///
/// Each entry comes with its scale: where the saturated switch's `1 - s` (rounded in both
/// computations) multiplies a term, that term with `1 - s` set to 1.
fn hand_leak_entries(m: &dyn Model, p: &[f64], x: &[f64]) -> Vec<(String, String, f64, f64)> {
    let v = |name: &str| p[m.param_index(name).unwrap()];
    let names = m.state_names();
    let s = |name: &str| names.iter().position(|q| q == name).unwrap();
    let n = m.n();
    let (r, g) = (v("R"), v("gamma"));
    let cp = g * r / (g - 1.0);
    let (eps, rl) = (v("mdot_eps"), v("Rl") * n as f64);
    let vessels = m.vessel_names();
    let (mut pr, mut vol) = (vec![0.0; vessels.len()], vec![0.0; vessels.len()]);
    m.pv(p, x, &mut pr, &mut vol);
    let vv = |name: &str| vol[vessels.iter().position(|q| q == name).unwrap()];
    let (pb, mb, vb) = (x[s("P_bounce")], x[s("m_bounce")], vv("bounce"));
    let tb = pb * vb / (mb * r);
    let mut out = Vec::new();
    for j in 0..n {
        let (pj, mj, vj) = (
            x[s(&format!("P_r[{j}]"))],
            x[s(&format!("m_r[{j}]"))],
            vv(&format!("r[{j}]")),
        );
        let tj = pj * vj / (mj * r);
        let md = (pj - pb) / rl;
        let th = (md / eps).tanh();
        let sw = 0.5 * (1.0 + th);
        let dsw = 0.5 * (1.0 - th * th) / eps; // ds/dmdot
        let tup = tb + sw * (tj - tb);
        // dH/dP_b and dH/dP_j
        let dh_dpb = cp * (-tup / rl + md * (-dsw / rl * (tj - tb) + (1.0 - sw) * tb / pb));
        let dh_dpj = cp * (tup / rl + md * (dsw / rl * (tj - tb) + sw * tj / pj));
        // dT_b/dx = T_b Ar / V_b, dT_b/dy = T_b (A - Ar) / V_b
        let dh_dtb = cp * md * (1.0 - sw);
        let (ar, a) = (v("Ar"), v("A"));
        let row = format!("P_r[{j}]");
        let k = (g - 1.0) / vj;
        let unsat = (k * cp * md * tb).abs();
        let dpb = -k * dh_dpb;
        out.push((row.clone(), "P_bounce".into(), dpb, dpb.abs() + unsat / pb));
        if j > 0 && j + 1 < n {
            // the end sections see `x` through the hot and cold CVs as well
            let dx = -k * dh_dtb * tb * ar / vb;
            out.push((row.clone(), "x".into(), dx, unsat * ar / vb));
            let dy = -k * dh_dtb * tb * (a - ar) / vb;
            out.push((row.clone(), "y".into(), dy, unsat * (a - ar) / vb));
        }
        out.push((
            row.clone(),
            "m_bounce".into(),
            k * dh_dtb * tb / mb,
            unsat / mb,
        ));
        out.push((format!("m_r[{j}]"), "P_bounce".into(), 1.0 / rl, 1.0 / rl));
        let dpj = (g - 1.0) / vb * dh_dpj;
        let sat = ((g - 1.0) / vb * cp * md * tj / pj).abs();
        out.push(("P_bounce".into(), format!("P_r[{j}]"), dpj, dpj.abs() + sat));
        out.push(("m_bounce".into(), format!("P_r[{j}]"), 1.0 / rl, 1.0 / rl));
    }
    out
}

/// The analytic leak entries (the sections' rows in the bounce's columns and the bounce's
/// rows in the sections' pressure columns, i.e. the chain-rule loops) equal the hand derivation to
/// round-off (relative to each entry's scale) at n = 1..50, at wide and balanced spreads.
#[test]
fn leak_entries_match_hand_derivation() {
    for n in [1usize, 2, 3, 10, 50] {
        let m = LeakToCv::new(n, Closure::Full).unwrap();
        let p = m.default_params();
        let names = m.state_names();
        let s = |name: &str| names.iter().position(|q| q == name).unwrap();
        let mut rng = common::rng(2500 + 10 * n as u64);
        let ns = m.n_states();
        let mut worst = 0.0f64;
        for spread in [common::Spread::Wide, common::Spread::Balanced] {
            for _ in 0..3 {
                let x = common::random_state(&m, &p, spread, &mut rng);
                let jac = m.jacobian_dense(&p, &x, 0.0);
                for (row, col, val, scale) in hand_leak_entries(&m, &p, &x) {
                    let a = jac[s(&row) + ns * s(&col)];
                    let e = (a - val).abs() / scale;
                    worst = worst.max(e);
                    assert!(e < 1e-13, "n={n} d {row}/d {col}: {a:e} vs hand {val:e}");
                }
            }
        }
        eprintln!("n={n}: leak entries vs hand derivation, max relative difference {worst:.1e}");
    }
}

/// The sparse linear algebra (faer) takes the arrow-shaped Jacobian: a run of the closed
/// bounce model at n = 50 gives the same states as the dense route.
#[test]
fn sparse_and_dense_agree_at_n50() {
    use stirling::models::sim::{self, LinearSolverKind, SimOptions};
    let model = LeakToCv::new(50, Closure::Full).unwrap();
    let p = model.default_params();
    let mut x0 = vec![0.0; model.n_states()];
    model.equilibrium_guess(&p, &mut x0);
    x0[0] = 5e-3;
    let scale = sim::state_scale(&model, &p);
    let samples = sim::uniform_samples(0.02, 20);
    let run = |kind| {
        let opts = SimOptions {
            rtol: 1e-10,
            atol: 1e-10,
            linear_solver: kind,
            ..SimOptions::default()
        };
        sim::simulate(&model, &p, &x0, 0.02, &samples, &opts).unwrap()
    };
    let (d, s) = (run(LinearSolverKind::Dense), run(LinearSolverKind::Sparse));
    assert_eq!(d.x.len(), s.x.len());
    let mut worst = 0.0f64;
    for (a, b) in d.x.iter().zip(&s.x) {
        for ((u, v), w) in a.iter().zip(b).zip(&scale) {
            worst = worst.max((u - v).abs() / w);
        }
    }
    eprintln!(
        "n = 50 arrow: max scaled difference {worst:.3e}; dense {:?}, sparse {:?}",
        d.stats, s.stats
    );
    assert!(worst < 1e-6, "dense and sparse runs differ by {worst:e}");
}
