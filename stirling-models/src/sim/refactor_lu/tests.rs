//! Tests of the refactoring LU: against nalgebra's dense LU, every column order, the pivot
//! test's fallbacks, the diagonal pattern.

use super::*;
use faer::sparse::{SparseColMat, Triplet};
use nalgebra::{DMatrix, DVector};

fn sparse(d: &DMatrix<f64>) -> SparseColMat<usize, f64> {
    let n = d.nrows();
    let mut trip = Vec::new();
    for c in 0..n {
        for r in 0..n {
            if d[(r, c)] != 0.0 || r == c {
                trip.push(Triplet::new(r, c, d[(r, c)]));
            }
        }
    }
    SparseColMat::try_new_from_triplets(n, n, &trip).expect("matrix")
}

/// A banded matrix with a dense border (the shape of a regenerator chain with bodies),
/// values varied by `s`.
fn matrix(n: usize, s: f64) -> DMatrix<f64> {
    let mut d = DMatrix::zeros(n, n);
    for i in 0..n {
        d[(i, i)] = 4.0 + s * (i as f64 * 0.37).sin();
        if i + 1 < n {
            d[(i, i + 1)] = -1.0 + 0.3 * s * (i as f64).cos();
            d[(i + 1, i)] = -1.5 + 0.2 * s;
        }
        d[(i, 0)] += 0.1 * (1.0 + i as f64 * 0.01);
        // never zero: the pattern is the same at every `s`, as `factor` requires
        d[(0, i)] += 0.2 * s + 0.01;
    }
    d
}

fn rhs(n: usize) -> Vec<f64> {
    (0..n).map(|i| 1.0 + (i as f64 * 0.7).cos()).collect()
}

fn check(x: &[f64], d: &DMatrix<f64>) {
    let want = d
        .clone()
        .lu()
        .solve(&DVector::from_vec(rhs(d.nrows())))
        .expect("dense");
    for i in 0..x.len() {
        assert!(
            (x[i] - want[i]).abs() < 1e-12 * (1.0 + want[i].abs()),
            "x[{i}]"
        );
    }
}

#[test]
fn refactorization_solves_as_the_dense_lu() {
    let d0 = matrix(40, 0.0);
    let a0 = sparse(&d0);
    let mut lu = RefactorLu::new(a0.symbolic());
    let mut kept = Vec::new();
    for s in [0.0, 0.3, 0.7, 1.1] {
        let d = matrix(40, s);
        lu.factor(sparse(&d).as_ref()).expect("regular");
        let mut x = rhs(40);
        lu.solve(&mut x).expect("solve");
        check(&x, &d);
        kept.push((lu.snapshot().expect("factored"), d));
    }
    assert_eq!((lu.full, lu.refactored), (0, 4), "the diagonal pivots held");
    // several columns at once: each as the one-column solve
    let (d, k) = (matrix(40, 1.1), 3);
    let mut xs: Vec<f64> = (0..k)
        .flat_map(|c| rhs(40).into_iter().map(move |v| v * (c + 1) as f64))
        .collect();
    lu.solve_columns(&mut xs, k, &mut Vec::new())
        .expect("solve");
    for c in 0..k {
        let one: Vec<f64> = xs[c * 40..(c + 1) * 40]
            .iter()
            .map(|v| v / (c + 1) as f64)
            .collect();
        check(&one, &d);
    }
    // the kept factors still solve their own matrices
    let mut work = vec![0.0; 40];
    for (snap, d) in &kept {
        let mut x = rhs(40);
        snap.solve(&mut x, &mut work);
        check(&x, d);
    }
}

#[test]
fn every_column_order_solves_as_the_dense_lu_with_its_own_fill() {
    let d = matrix(40, 0.7);
    let a = sparse(&d);
    let nnz = a.compute_nnz();
    for order in ColumnOrder::ALL {
        let mut lu = RefactorLu::with_order(a.symbolic(), order).partial_pivoting_only();
        lu.factor(a.as_ref()).expect("regular");
        assert_eq!(lu.full, 1, "{order:?}: partial pivoting ran");
        let mut x = rhs(40);
        lu.solve(&mut x).expect("factored");
        check(&x, &d);
        assert!(
            lu.factor_entries() >= nnz,
            "{order:?}: {} < {nnz}",
            lu.factor_entries()
        );
    }
}

#[test]
fn a_pivot_gone_small_starts_a_new_pivoting() {
    // [[a, 1], [1, 1]]: pivots kept from a = 2 fail when a -> 1e-9
    let build = |a: f64| DMatrix::from_row_slice(2, 2, &[a, 1.0, 1.0, 1.0]);
    let mut lu = RefactorLu::new(sparse(&build(2.0)).symbolic()).partial_pivoting_only();
    lu.factor(sparse(&build(2.0)).as_ref()).expect("regular");
    let kept = lu.snapshot().expect("factored");
    lu.factor(sparse(&build(1e-9)).as_ref()).expect("regular");
    assert_eq!(lu.full, 2, "the tiny pivot was not caught");
    let mut x = rhs(2);
    lu.solve(&mut x).expect("solve");
    check(&x, &build(1e-9));
    // a snapshot taken before the new pivoting keeps its own pattern
    let mut x = rhs(2);
    kept.solve(&mut x, &mut [0.0; 2]);
    check(&x, &build(2.0));
}

#[test]
fn a_singular_matrix_is_an_error() {
    let a = sparse(&DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]));
    let mut lu = RefactorLu::new(a.symbolic());
    assert_eq!(lu.factor(a.as_ref()), Err(Singular));
    assert_eq!(lu.solve(&mut [1.0, 1.0]), Err(Singular));
    assert!(lu.snapshot().is_err());
}

/// A volume's (pressure, mass) pair as in `I - c J` of the regenerator chain: the mass column
/// holds 1 on the diagonal and `big` in the pressure's row, the mass row only `tiny` entries.
fn pair(big: f64, tiny: f64, diag: f64) -> DMatrix<f64> {
    DMatrix::from_row_slice(3, 3, &[diag, big, 0.5, tiny, 1.0, 0.0, 0.3, 0.0, 2.0])
}

#[test]
fn the_diagonal_holds_where_the_row_test_passes_and_saves_the_fill() {
    // the mass pivot (1) fails the column test (1e7 below it) and passes the row test (1e-8)
    let d = pair(1e7, 1e-8, 10.0);
    let a = sparse(&d);
    let mut lu = RefactorLu::new(a.symbolic());
    lu.factor(a.as_ref()).expect("regular");
    assert!(lu.on_diagonal(), "the diagonal pattern was not kept");
    assert_eq!(lu.full, 0);
    let mut x = rhs(3);
    lu.solve(&mut x).expect("solve");
    check(&x, &d);
    // on the regenerator-like chain too, with fewer factor entries than partial pivoting
    let d = matrix(40, 0.7);
    let a = sparse(&d);
    let mut diag = RefactorLu::new(a.symbolic());
    diag.factor(a.as_ref()).expect("regular");
    let mut partial = RefactorLu::new(a.symbolic()).partial_pivoting_only();
    partial.factor(a.as_ref()).expect("regular");
    assert!(diag.on_diagonal() && !partial.on_diagonal());
    assert!(diag.factor_entries() <= partial.factor_entries());
}

#[test]
fn a_diagonal_failing_both_tests_falls_back_to_partial_pivoting() {
    // the mass row now holds entries as large as the pressure's: the pivot 1 fails both
    let d = pair(1e7, 1e7, 10.0);
    let a = sparse(&d);
    let mut lu = RefactorLu::new(a.symbolic());
    lu.factor(a.as_ref()).expect("regular");
    assert!(!lu.on_diagonal(), "a pivot failing both tests was kept");
    assert_eq!(lu.full, 1);
    let mut x = rhs(3);
    lu.solve(&mut x).expect("solve");
    check(&x, &d);
    // a later matrix whose kept (partial) pivots fail is still solved right
    let d = pair(1e7, 1e-8, 1e-12);
    lu.factor(sparse(&d).as_ref()).expect("regular");
    let mut x = rhs(3);
    lu.solve(&mut x).expect("solve");
    check(&x, &d);
}
