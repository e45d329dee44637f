//! A sparse LU that keeps its pivot sequence between factorizations: KLU's
//! *refactorization*, for the Newton matrices `I - c J` of the stiff integrator.
//!
//! The first factorization is faer's left-looking (Gilbert-Peierls) simplicial LU with
//! partial pivoting on a COLAMD column order. Every later one reuses its row pivots and the
//! patterns of `L` and `U`: the numeric work of Gilbert-Peierls without the depth-first
//! search for each column's reach, and the solve is two plain column sweeps over our own
//! arrays (faer's solve copies the right-hand side through two row permutations, which cost
//! as much as the triangular sweeps on `nsection` at n = 100).
//!
//! A kept pivot can go bad when the matrix drifts (the step size and the Jacobian change
//! from factorization to factorization); a pivot smaller than [`PIVOT_TOLERANCE`] times the
//! largest entry below it in its column, or not finite, makes the factorization start over
//! with fresh partial pivoting. A matrix singular even then is an error at the solve, which
//! the integrator treats as a failed step.
//!
//! Why our own: neither faer nor diffsol has a refactorization with a fixed pivot sequence,
//! and KLU itself is C (SuiteSparse) that the project does not otherwise need.

use std::cell::RefCell;

use diffsol::{FaerContext, FaerSparseMat, FaerVec, LaError, Matrix, MatrixCommon, Vector};
use diffsol_la::error::LinearSolverError;
use diffsol_la::{LinearOp, LinearSolver};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::factorize_symbolic_lu;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::SparseColMatRef;

/// A kept pivot smaller than this times the largest entry below it starts a new pivoting.
pub const PIVOT_TOLERANCE: f64 = 1e-3;

/// The factors in the permuted order: `P A Q = L U`, `L` unit lower triangular (its
/// diagonal stored first in each column), `U` upper triangular (its diagonal stored last,
/// the other entries of a column in an order that is topological for the solve with `L`).
#[derive(Default)]
struct Factors {
    l_ptr: Vec<usize>,
    l_idx: Vec<usize>,
    l_val: Vec<f64>,
    u_ptr: Vec<usize>,
    u_idx: Vec<usize>,
    u_val: Vec<f64>,
    /// `1 / U[j, j]` (the solve multiplies).
    u_inv_diag: Vec<f64>,
    /// Permuted row `i` is original row `row_perm[i]`; `row_inv` is the inverse.
    row_perm: Vec<usize>,
    row_inv: Vec<usize>,
}

/// The refactoring sparse LU (see the module doc).
#[derive(Default)]
pub struct RefactorLu {
    a: Option<FaerSparseMat<f64>>,
    /// Column `j` of `A Q` is column `col_perm[j]` of `A`; `col_inv` is the inverse.
    col_perm: Vec<usize>,
    col_inv: Vec<usize>,
    f: Factors,
    /// Whether `f` holds a usable factorization of the current matrix.
    ok: bool,
    work: Vec<f64>,
    solve_work: RefCell<Vec<f64>>,
    stack: Option<MemBuffer>,
    /// Factorizations with fresh pivoting, and those that reused the pivots.
    pub full: usize,
    pub refactored: usize,
}

impl RefactorLu {
    /// Analyse the pattern of `a` (column order) and keep the matrix storage.
    pub fn with_pattern(a: FaerSparseMat<f64>) -> Self {
        let sym = a.inner()[0].symbolic();
        let n = sym.ncols();
        let (col_perm, col_inv) = match factorize_symbolic_lu(sym, Default::default()) {
            Ok(s) => {
                let (fwd, inv) = s.col_perm().arrays();
                (fwd.to_vec(), inv.to_vec())
            }
            Err(_) => ((0..n).collect(), (0..n).collect()),
        };
        Self {
            stack: Some(MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<
                usize,
                f64,
            >(n, n))),
            a: Some(a),
            col_perm,
            col_inv,
            work: vec![0.0; n],
            solve_work: RefCell::new(vec![0.0; n]),
            ..Default::default()
        }
    }

    /// Factor the stored matrix: reuse the pivots when there are any and they hold.
    pub fn factor(&mut self) {
        let Some(a) = self.a.as_ref() else {
            self.ok = false;
            return;
        };
        let a = a.inner()[0].as_ref();
        if self.ok && refactor(&mut self.f, &mut self.work, a, &self.col_perm) {
            self.refactored += 1;
            return;
        }
        self.full += 1;
        let stack = self.stack.as_mut().expect("scratch allocated with the pattern");
        self.ok = full_factor(&mut self.f, a, &self.col_perm, &self.col_inv, stack);
    }

    /// `x <- A^-1 x`.
    pub fn solve(&self, x: &mut [f64]) -> Result<(), LaError> {
        if !self.ok {
            return Err(LinearSolverError::LuSolveFailed.into());
        }
        let f = &self.f;
        let mut y = self.solve_work.borrow_mut();
        let y = &mut y[..];
        for (yi, &r) in y.iter_mut().zip(&f.row_perm) {
            *yi = x[r];
        }
        let (lp, li, lv) = (&f.l_ptr[..], &f.l_idx[..], &f.l_val[..]);
        for j in 0..y.len() {
            let yj = y[j];
            let (a, b) = (lp[j] + 1, lp[j + 1]);
            for (&i, &v) in li[a..b].iter().zip(&lv[a..b]) {
                y[i] -= v * yj;
            }
        }
        let (up, ui, uv, dinv) = (&f.u_ptr[..], &f.u_idx[..], &f.u_val[..], &f.u_inv_diag[..]);
        for j in (0..y.len()).rev() {
            let yj = y[j] * dinv[j];
            y[j] = yj;
            let (a, b) = (up[j], up[j + 1] - 1);
            for (&i, &v) in ui[a..b].iter().zip(&uv[a..b]) {
                y[i] -= v * yj;
            }
        }
        for (&yj, &c) in y.iter().zip(&self.col_perm) {
            x[c] = yj;
        }
        Ok(())
    }
}

/// Partial pivoting from scratch (faer), then the factors copied into `f`. False when the
/// matrix is singular.
fn full_factor(
    f: &mut Factors,
    a: SparseColMatRef<'_, usize, f64>,
    col_perm: &[usize],
    col_inv: &[usize],
    stack: &mut MemBuffer,
) -> bool {
    let n = a.ncols();
    f.row_perm.resize(n, 0);
    f.row_inv.resize(n, 0);
    let mut lu = SimplicialLu::<usize, f64>::new();
    let q = PermRef::new_checked(col_perm, col_inv, n);
    let done = factorize_simplicial_numeric_lu(
        &mut f.row_perm,
        &mut f.row_inv,
        &mut lu,
        a,
        q,
        MemStack::new(stack),
    );
    if done.is_err() {
        return false;
    }
    let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
    copy_csc(l, &mut f.l_ptr, &mut f.l_idx, &mut f.l_val);
    copy_csc(u, &mut f.u_ptr, &mut f.u_idx, &mut f.u_val);
    f.u_inv_diag.clear();
    f.u_inv_diag.extend((0..n).map(|j| 1.0 / f.u_val[f.u_ptr[j + 1] - 1]));
    (0..n).all(|j| {
        let d = f.u_val[f.u_ptr[j + 1] - 1];
        d.is_finite() && d != 0.0 && f.u_idx[f.u_ptr[j + 1] - 1] == j
    })
}

fn copy_csc(
    m: SparseColMatRef<'_, usize, f64>,
    ptr: &mut Vec<usize>,
    idx: &mut Vec<usize>,
    val: &mut Vec<f64>,
) {
    ptr.clear();
    ptr.extend_from_slice(m.symbolic().col_ptr());
    idx.clear();
    idx.extend_from_slice(m.symbolic().row_idx());
    val.clear();
    val.extend_from_slice(m.val());
}

/// Gilbert-Peierls with the kept pivots and patterns. False (the factors then unusable)
/// when a pivot fails the tolerance.
fn refactor(
    f: &mut Factors,
    x: &mut [f64],
    a: SparseColMatRef<'_, usize, f64>,
    col_perm: &[usize],
) -> bool {
    let (ap, ai, av) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for (j, &c) in col_perm.iter().enumerate() {
        for e in ap[c]..ap[c + 1] {
            x[f.row_inv[ai[e]]] += av[e];
        }
        let last = f.u_ptr[j + 1] - 1;
        for e in f.u_ptr[j]..last {
            let r = f.u_idx[e];
            let xr = x[r];
            x[r] = 0.0;
            f.u_val[e] = xr;
            for k in f.l_ptr[r] + 1..f.l_ptr[r + 1] {
                x[f.l_idx[k]] -= f.l_val[k] * xr;
            }
        }
        let pivot = x[j];
        x[j] = 0.0;
        let below = &f.l_idx[f.l_ptr[j] + 1..f.l_ptr[j + 1]];
        let largest = below.iter().fold(0.0f64, |m, &i| m.max(x[i].abs()));
        let good = pivot.is_finite() && pivot.abs() > PIVOT_TOLERANCE * largest && pivot != 0.0;
        f.u_val[last] = pivot;
        f.u_inv_diag[j] = 1.0 / pivot;
        for k in f.l_ptr[j] + 1..f.l_ptr[j + 1] {
            let i = f.l_idx[k];
            f.l_val[k] = x[i] / pivot;
            x[i] = 0.0;
        }
        if !good {
            x.fill(0.0);
            return false;
        }
    }
    true
}

impl LinearSolver<FaerSparseMat<f64>> for RefactorLu {
    fn set_linearisation<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let a = self.a.as_mut().expect("the pattern is set first");
        op.matrix_inplace(a);
        self.factor();
    }

    fn solve_in_place(&self, x: &mut FaerVec<f64>) -> Result<(), LaError> {
        self.solve(x.inner_mut().col_as_slice_mut(0))
    }

    fn solve_transpose_in_place(&self, _x: &mut FaerVec<f64>) -> Result<(), LaError> {
        Err(LinearSolverError::Other("the refactoring LU has no transposed solve".into()).into())
    }

    fn set_sparsity<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let a =
            FaerSparseMat::new_from_sparsity(op.nrows(), op.ncols(), op.sparsity(), *op.context());
        *self = Self::with_pattern(a);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A banded matrix with a dense border (the shape of a regenerator chain with bodies),
    /// values varied by `s`.
    fn matrix(n: usize, s: f64) -> (FaerSparseMat<f64>, DMatrix<f64>) {
        let mut d = DMatrix::zeros(n, n);
        for i in 0..n {
            d[(i, i)] = 4.0 + s * (i as f64 * 0.37).sin();
            if i + 1 < n {
                d[(i, i + 1)] = -1.0 + 0.3 * s * (i as f64).cos();
                d[(i + 1, i)] = -1.5 + 0.2 * s;
            }
            d[(i, 0)] += 0.1 * (1.0 + i as f64 * 0.01);
            d[(0, i)] += 0.2 * s;
        }
        let mut trip = Vec::new();
        let mut vals = Vec::new();
        for c in 0..n {
            for r in 0..n {
                if d[(r, c)] != 0.0 || r == c {
                    trip.push((r, c));
                    vals.push(d[(r, c)]);
                }
            }
        }
        let m = FaerSparseMat::try_from_triplets(n, n, trip, vals, FaerContext::default())
            .expect("matrix");
        (m, d)
    }

    fn solve_matches(lu: &RefactorLu, d: &DMatrix<f64>) {
        let n = d.nrows();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.7).cos()).collect();
        let mut x = b.clone();
        lu.solve(&mut x).expect("solve");
        let want = d.clone().lu().solve(&DVector::from_vec(b)).expect("dense");
        for i in 0..n {
            assert!((x[i] - want[i]).abs() < 1e-12 * (1.0 + want[i].abs()), "x[{i}]");
        }
    }

    #[test]
    fn refactorization_solves_as_the_dense_lu() {
        let (m, d) = matrix(40, 0.0);
        let mut lu = RefactorLu::with_pattern(m.clone());
        lu.factor();
        solve_matches(&lu, &d);
        for s in [0.3, 0.7, 1.1] {
            let (m2, d2) = matrix(40, s);
            lu.a = Some(m2);
            lu.factor();
            solve_matches(&lu, &d2);
        }
        assert_eq!((lu.full, lu.refactored), (1, 3));
    }

    #[test]
    fn a_pivot_gone_small_starts_a_new_pivoting() {
        // [[a, 1], [1, 1]]: pivots kept from a = 2 fail when a -> 1e-9
        let build = |a: f64| {
            FaerSparseMat::try_from_triplets(
                2,
                2,
                vec![(0, 0), (1, 0), (0, 1), (1, 1)],
                vec![a, 1.0, 1.0, 1.0],
                FaerContext::default(),
            )
            .expect("matrix")
        };
        let mut lu = RefactorLu::with_pattern(build(2.0));
        lu.factor();
        lu.a = Some(build(1e-9));
        lu.factor();
        assert_eq!(lu.full, 2, "the tiny pivot was not caught");
        let d = DMatrix::from_row_slice(2, 2, &[1e-9, 1.0, 1.0, 1.0]);
        solve_matches(&lu, &d);
    }

    #[test]
    fn a_singular_matrix_is_an_error_at_the_solve() {
        let m = FaerSparseMat::try_from_triplets(
            2,
            2,
            vec![(0, 0), (1, 0), (0, 1), (1, 1)],
            vec![1.0, 2.0, 2.0, 4.0],
            FaerContext::default(),
        )
        .expect("matrix");
        let mut lu = RefactorLu::with_pattern(m);
        lu.factor();
        let mut x = vec![1.0, 1.0];
        assert!(lu.solve(&mut x).is_err());
    }
}
