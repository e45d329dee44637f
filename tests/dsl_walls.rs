//! Walls with a temperature state (thermal masses) declared with `stirling_model!`: the
//! generated Jacobians against finite differences, the energy budget with the walls' `C Tw`,
//! and the limits of large and small capacity.

mod common;
#[path = "dsl_walls/models.rs"]
mod models;

use models::{Fixed, HeadMatrix, HeadWall, MatrixShell, MatrixWall, OneWall};
use stirling::dsl::{Closure, Model, StateKind, Style};

#[test]
fn rest_state_is_an_equilibrium() {
    for n in [1, 2, 3, 10] {
        let models: [Box<dyn Model>; 4] = [
            Box::new(Fixed::new(n, Closure::Full).unwrap()),
            Box::new(HeadWall::new(n, Closure::Full).unwrap()),
            Box::new(MatrixWall::new(n, Closure::Full).unwrap()),
            Box::new(HeadMatrix::new(n, Closure::Full).unwrap()),
        ];
        for m in &models {
            let p = m.default_params();
            let mut x = vec![0.0; m.n_states()];
            m.equilibrium_guess(&p, &mut x);
            let mut f = vec![0.0; m.n_states()];
            m.rhs(&p, &x, 0.0, &mut f);
            for ((s, fi), xi) in m.states().iter().zip(&f).zip(&x) {
                let scale = match s.kind {
                    StateKind::Pressure(_) => 1e5,
                    StateKind::WallTemperature(_) => *xi,
                    _ => 1.0,
                };
                assert!(
                    fi.abs() <= 1e-9 * scale,
                    "{} n={n}: {}' = {fi:e} at rest",
                    m.name(),
                    s.name
                );
            }
        }
    }
}

/// The printed equations of a small model with one wall (review them like code).
#[test]
fn one_wall_equations_text() {
    let m = OneWall::new(1, Closure::Full).unwrap();
    insta::assert_snapshot!("one_wall_equations", m.equations(Style::Text));
}

fn all(n: usize, closure: Closure) -> Vec<Box<dyn Model>> {
    let mut v: Vec<Box<dyn Model>> = vec![
        Box::new(HeadWall::new(n, closure).unwrap()),
        Box::new(MatrixWall::new(n, closure).unwrap()),
        Box::new(HeadMatrix::new(n, closure).unwrap()),
    ];
    if n == 1 {
        v.push(Box::new(OneWall::new(1, closure).unwrap()));
    }
    // per-section ports and conduction into one shared wall (the shell)
    v.push(Box::new(MatrixShell::new(n, closure).unwrap()));
    v
}

/// The generated Jacobian and parameter Jacobian against Ridders-extrapolated central
/// differences (relative 1e-6 on entries above 1e-8 of their scaled row or column maximum),
/// at 4 seeded random states of each pressure spread.
#[test]
fn jacobians_match_finite_differences() {
    for n in [1, 2, 3, 10, 50] {
        let closures: &[Closure] = if n <= 3 {
            &[Closure::Full, Closure::Frozen]
        } else {
            &[Closure::Full]
        };
        for &closure in closures {
            for (k, m) in all(n, closure).iter().enumerate() {
                let label = format!("{} n={n} ({closure})", m.name());
                common::assert_jacobians(m.as_ref(), &label, 1000 + 10 * n as u64 + k as u64, 4);
            }
        }
    }
}

/// docs/physics.md section 10 with walls: `d/dt (gas + walls + mechanics) = heat from outside
/// + boundary + mechanical`, to round-off at random states; the gas mass does not change.
#[test]
fn energy_budget_holds_with_walls() {
    let mut worst = 0.0f64;
    for n in [1, 2, 3, 10, 50] {
        for m in all(n, Closure::Full) {
            let p = m.default_params();
            let mut rng = common::rng(77 + n as u64);
            for spread in [common::Spread::Wide, common::Spread::Balanced] {
                for _ in 0..4 {
                    let x = common::random_state(m.as_ref(), &p, spread, &mut rng);
                    let (de, terms, scale) = common::energy_rate(m.as_ref(), &p, &x);
                    let gap = (de - terms).abs() / scale;
                    worst = worst.max(gap);
                    assert!(
                        gap < 1e-15,
                        "{} n={n}: dE/dt {de:e} vs terms {terms:e}",
                        m.name()
                    );
                    let (dm, size) = common::mass_rate(m.as_ref(), &p, &x);
                    assert!(
                        dm.abs() <= 1e-14 * size,
                        "{} n={n}: dm/dt {dm:e} of {size:e}",
                        m.name()
                    );
                }
            }
        }
    }
    eprintln!(
        "energy budget: max |dE/dt - terms| = {worst:.2e} of the round-off scale E/h + sum |P' V|"
    );
}

/// The Jacobian's nonzeros grow linearly with `n` (the wall block is tridiagonal and couples
/// only to its own gas section), and the sparse LU integrates the matrix model as the dense
/// one does.
#[test]
fn sparse_route_takes_the_walls() {
    use stirling::models::sim::{self, LinearSolverKind, SimOptions};
    let nnz = |n: usize| {
        let m = HeadMatrix::new(n, Closure::Full).unwrap();
        m.sparsity(&m.default_params()).len()
    };
    let (a, b) = (nnz(100), nnz(200));
    eprintln!("nonzeros: {a} at n = 100, {b} at n = 200");
    assert!(b - a == nnz(300) - b, "nonzeros linear in n: {a}, {b}");
    let m = HeadMatrix::new(50, Closure::Full).unwrap();
    let p = m.default_params();
    let mut x0 = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x0);
    x0[0] = 5e-3;
    let run = |kind| {
        let opts = SimOptions {
            linear_solver: kind,
            rtol: 1e-8,
            atol: 1e-8,
            ..Default::default()
        };
        sim::simulate(&m, &p, &x0, 0.05, &[0.05], &opts).unwrap()
    };
    let (sparse, dense) = (run(LinearSolverKind::Sparse), run(LinearSolverKind::Dense));
    let scale = common::state_scales(&m, &p);
    let gap = sparse
        .x_end
        .iter()
        .zip(&dense.x_end)
        .zip(&scale)
        .map(|((a, b), s)| (a - b).abs() / s)
        .fold(0.0, f64::max);
    eprintln!("sparse vs dense after 0.05 s at n = 50: max scaled difference {gap:.2e}");
    assert!(gap < 1e-4, "{gap:e}");
}

/// Per-section ports and conduction links into one shared wall: the shell's row sums over the
/// sections in one O(n) loop and its column is dense (an arrow), so the Jacobian's nonzeros
/// still grow linearly with `n`; the shell's row holds the exact sums.
#[test]
fn shared_wall_is_an_arrow_linear_in_n() {
    let nnz = |n: usize| {
        let m = MatrixShell::new(n, Closure::Full).unwrap();
        m.sparsity(&m.default_params()).len()
    };
    let (a, b, c) = (nnz(100), nnz(200), nnz(300));
    eprintln!("shared wall: nonzeros {a} at n = 100, {b} at n = 200, {c} at n = 300");
    assert!(b - a == c - b, "nonzeros linear in n: {a}, {b}, {c}");
    // the shell's row against its hand-written sum at a random state
    for n in [1, 3, 10] {
        let m = MatrixShell::new(n, Closure::Full).unwrap();
        let p = m.default_params();
        let mut rng = common::rng(4242 + n as u64);
        let x = common::random_state(&m, &p, common::Spread::Wide, &mut rng);
        let mut f = vec![0.0; m.n_states()];
        m.rhs(&p, &x, 0.0, &mut f);
        let states = m.states();
        let idx = |name: &str| states.iter().position(|s| s.name == name).unwrap();
        let names = MatrixShell::PARAMS
            .iter()
            .map(|q| q.name)
            .collect::<Vec<_>>();
        let par = |name: &str| p[names.iter().position(|q| *q == name).unwrap()];
        let mut temps = vec![0.0; m.n_states()];
        m.temperatures(&p, &x, &mut temps);
        let vessels = m.vessel_names();
        let ts = x[idx("Tw_shell")];
        let (hs, aws, gms, gs, tk, ks) = (
            par("hs"),
            par("Aws"),
            par("Gms"),
            par("Gs"),
            par("Tk"),
            par("ks"),
        );
        let mut q = -gs * (ts - tk);
        for j in 0..n {
            let tg = temps[vessels
                .iter()
                .position(|v| *v == format!("r[{j}]"))
                .unwrap()];
            let tm = x[idx(&format!("Tw_matrix[{j}]"))];
            q += hs * aws / n as f64 * (tg - ts) + gms / n as f64 * (tm - ts);
        }
        let want = ks * q;
        let got = f[idx("Tw_shell")];
        assert!(
            (got - want).abs() <= 1e-12 * want.abs().max(1e-12),
            "n={n}: Tw_shell' {got:e} vs hand {want:e}"
        );
    }
}

/// The bond graph (DOT) draws the walls: 0-junctions with their capacitances and heat
/// inputs, the ports to them and the conduction links (review it like code).
#[test]
fn walls_dot() {
    use stirling::dsl::bond::bond_graph;
    let m = HeadMatrix::new(3, Closure::Full).unwrap();
    insta::assert_snapshot!("head_matrix_dot", bond_graph(&m).unwrap().to_dot());
    let m = MatrixShell::new(3, Closure::Full).unwrap();
    insta::assert_snapshot!("matrix_shell_dot", bond_graph(&m).unwrap().to_dot());
}
