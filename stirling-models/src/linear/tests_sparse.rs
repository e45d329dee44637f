//! The sparse route against the dense one: equilibrium, dominant poles, `L(jw)`.

use stirling_dsl::{Closure, Model};

use super::dominant::{dominant_poles_with, DominantOptions};
use super::equilibrium::{self, mass_states, state_scales, NewtonOptions, NewtonSolver};
use super::sparse::{solve_constrained, solve_real, SparseMatrix};
use super::{dynamic_poles_with, linearize, LinearOptions, PoleRequest, PoleRoute};

fn nsection(n: usize) -> (Box<dyn Model>, Vec<f64>) {
    let m = crate::build("nsection", Some(n), Closure::Full).unwrap();
    let p = m.default_params();
    (m, p)
}

fn rel(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1) / b.0.hypot(b.1)
}

#[test]
fn sparse_equilibrium_equals_dense() {
    for n in [10, 50] {
        let (m, p) = nsection(n);
        let mut x0 = vec![0.0; m.n_states()];
        m.equilibrium_guess(&p, &mut x0);
        let o = NewtonOptions::default();
        let d = equilibrium::solve_with(m.as_ref(), &p, &x0, &o, NewtonSolver::Dense).unwrap();
        let s = equilibrium::solve_with(m.as_ref(), &p, &x0, &o, NewtonSolver::Sparse).unwrap();
        assert_eq!(d.iterations, s.iterations, "n = {n}");
        assert!(s.scaled_residual <= o.tol);
        let sc = state_scales(m.as_ref(), &d.x);
        for i in 0..d.x.len() {
            assert!(
                (d.x[i] - s.x[i]).abs() <= 1e-9 * sc[i],
                "n = {n}, state {i}: {} vs {}",
                d.x[i],
                s.x[i]
            );
        }
    }
}

/// The constrained solve (one row replaced by the inventory constraint, by Sherman-Morrison
/// on a sparse matrix) equals the direct factorization of the matrix with that dense row.
#[test]
fn constrained_solve_equals_the_dense_row_system() {
    let (m, p) = nsection(20);
    let mut x = vec![0.0; m.n_states()];
    m.equilibrium_guess(&p, &mut x);
    let a = SparseMatrix {
        n: x.len(),
        entries: m.jacobian_triplets(&p, &x, 0.0),
    };
    let masses = mass_states(m.as_ref());
    let last = *masses.last().unwrap();
    let b: Vec<f64> = (0..a.n)
        .map(|i| ((i * 7 % 11) as f64 - 5.0) * 1e-3)
        .collect();
    let mut direct = a.clone();
    direct.entries.retain(|e| e.0 != last);
    direct
        .entries
        .extend(masses.iter().map(|&i| (last, i, 1.0)));
    let x_direct = solve_real(&direct, &b).unwrap().unwrap();
    let x_sm = solve_constrained(&a, last, &masses, &b).unwrap().unwrap();
    let big = x_direct.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (u, v)) in x_sm.iter().zip(&x_direct).enumerate() {
        assert!((u - v).abs() <= 1e-9 * big, "state {i}: {u} vs {v}");
    }
    // and it satisfies the constraint row
    let sum: f64 = masses.iter().map(|&i| x_sm[i]).sum();
    assert!((sum - b[last]).abs() <= 1e-9 * big.max(b[last].abs()));
}

/// The dense reference itself is accurate to about `eps |A| kappa / |lambda|` (`|A|` ~ 1e7 1/s
/// at n = 200 from the pressure-equalization modes): 1.7e-8 relative for the working pair at
/// n = 200, where the Ritz values of four different shifts agree with each other to 1e-11. Hence
/// 1e-8 up to n = 50 and 3e-8 at n = 200.
#[test]
fn dominant_poles_equal_the_dense_ones() {
    for (n, tol) in [(10, 1e-8), (50, 1e-8), (200, 3e-8)] {
        let (m, p) = nsection(n);
        let o = NewtonOptions::default();
        let dense = dynamic_poles_with(m.as_ref(), &p, &o, PoleRequest::All).unwrap();
        let sparse = dynamic_poles_with(m.as_ref(), &p, &o, PoleRequest::Dominant(4)).unwrap();
        assert!(matches!(sparse.route, PoleRoute::SparseDominant { .. }));
        assert!(sparse.poles.len() >= 4, "n = {n}: {:?}", sparse.poles);
        // The two rightmost pairs agree in order.
        let mut worst = 0.0f64;
        for (s, d) in sparse.poles.iter().zip(&dense.poles).take(4) {
            let e = rel((s.re, s.im), (d.re, d.im));
            worst = worst.max(e);
            assert!(e < tol, "n = {n}: {s:?} vs {d:?} ({e:.1e})");
        }
        eprintln!("n = {n}: max relative difference of the two rightmost pairs {worst:.2e}");
        // Every returned pole is a pole of the dense route.
        for s in &sparse.poles {
            let e = dense
                .poles
                .iter()
                .map(|d| rel((s.re, s.im), (d.re, d.im)))
                .fold(f64::INFINITY, f64::min);
            assert!(
                e < 1e-6,
                "n = {n}: {s:?} not among the dense poles ({e:.1e})"
            );
        }
    }
}

#[test]
fn the_inventory_zero_is_never_returned() {
    let (m, p) = nsection(10);
    let eq = equilibrium::solve(m.as_ref(), &p, &NewtonOptions::default()).unwrap();
    let a = SparseMatrix {
        n: eq.x.len(),
        entries: m.jacobian_triplets(&p, &eq.x, 0.0),
    };
    // Shifts right next to the origin: without the constraint the zero would be nearest.
    let opts = DominantOptions {
        k: 6,
        band_rad_s: (1e-4, 1e-2),
        ..Default::default()
    };
    let d = dominant_poles_with(
        &a,
        &state_scales(m.as_ref(), &eq.x),
        &mass_states(m.as_ref()),
        &opts,
    )
    .unwrap();
    assert!(!d.poles.is_empty());
    for q in &d.poles {
        assert!(q.natural_rad_s > 1e-6, "inventory zero returned: {q:?}");
    }
}

#[test]
fn sparse_loop_response_equals_the_dense_one() {
    let (m, p) = nsection(10);
    let run = |poles| {
        let o = LinearOptions {
            poles,
            ..Default::default()
        };
        linearize(m.as_ref(), &p, &o).unwrap()
    };
    let (d, s) = (run(PoleRequest::All), run(PoleRequest::Dominant(4)));
    for w in [0.0, 1.0, 30.0, 300.0, 3e3, 3e4] {
        let (ld, ls) = (d.open_loop.at(w), s.open_loop.at(w));
        assert!(
            (ld - ls).norm() <= 1e-8 * ld.norm(),
            "w = {w}: {ld} vs {ls}"
        );
    }
    let (od, os) = (&d.open_loop.poles[0], &s.open_loop.poles[0]);
    assert!(
        rel((os.re, os.im), (od.re, od.im)) < 1e-8,
        "{os:?} vs {od:?}"
    );
}
