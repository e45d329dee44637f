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
//! A kept pivot can go bad when the matrix drifts (the step size and the Jacobian change from
//! factorization to factorization); a pivot smaller than
//! [`PIVOT_TOLERANCE`](crate::sim::refactor_lu::PIVOT_TOLERANCE) times the largest entry below it
//! in its column, or not finite, makes the factorization start over with fresh partial pivoting. A
//! matrix singular even then is an error at the solve, which the integrator treats as a failed
//! step.
//!
//! The factors of one matrix can be kept ([`LuSnapshot`](crate::sim::refactor_lu::LuSnapshot): the
//! values only, the pattern is shared while the pivots hold), which is how the tangent route stores
//! one factorization per step of a period at half the memory of faer's factors.
//!
//! Why our own: neither faer nor diffsol has a refactorization with a fixed pivot sequence,
//! and KLU itself is C (SuiteSparse) that the project does not otherwise need.

mod order;
mod rcm;
mod solve;

use std::cell::RefCell;
use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

pub use order::ColumnOrder;
use solve::{solve_many, solve_with};

/// A kept pivot smaller than this times the largest entry below it starts a new pivoting.
pub const PIVOT_TOLERANCE: f64 = 1e-3;

/// The matrix is singular (or the factorization was never done).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("singular matrix in the sparse LU")]
pub struct Singular;

/// The pivot order and the patterns of `P A Q = L U`: `L` unit lower triangular (its
/// diagonal stored first in each column), `U` upper triangular (its diagonal stored last,
/// the other entries of a column in an order that is topological for the solve with `L`).
#[derive(Debug, Default)]
struct LuPattern {
    l_ptr: Vec<usize>,
    l_idx: Vec<usize>,
    u_ptr: Vec<usize>,
    u_idx: Vec<usize>,
    /// Permuted row `i` is original row `row_perm[i]`; `row_inv` is the inverse.
    row_perm: Vec<usize>,
    row_inv: Vec<usize>,
    /// Column `j` of `A Q` is column `col_perm[j]` of `A`.
    col_perm: Vec<usize>,
}

/// The values of one factorization on its [`LuPattern`].
#[derive(Clone, Debug, Default)]
struct LuValues {
    l: Vec<f64>,
    u: Vec<f64>,
    /// `1 / U[j, j]` (the solve multiplies).
    u_inv_diag: Vec<f64>,
}

/// One factorization kept for later solves.
#[derive(Clone, Debug)]
pub struct LuSnapshot {
    pattern: Arc<LuPattern>,
    values: LuValues,
}

impl LuSnapshot {
    /// `x <- A^-1 x`; `work` of the matrix's size.
    pub fn solve(&self, x: &mut [f64], work: &mut [f64]) {
        solve_with(&self.pattern, &self.values, x, work);
    }

    /// `X <- A^-1 X` for the `k` columns of `x` (column-major); `work` is resized to `n k`.
    pub fn solve_columns(&self, x: &mut [f64], k: usize, work: &mut Vec<f64>) {
        solve_many(&self.pattern, &self.values, x, k, work);
    }

    /// Bytes of the values (the pattern is shared).
    pub fn bytes(&self) -> usize {
        8 * (self.values.l.len() + self.values.u.len() + self.values.u_inv_diag.len())
    }
}

/// The refactoring sparse LU of matrices of one pattern (see the module doc).
pub struct RefactorLu {
    pattern: Arc<LuPattern>,
    values: LuValues,
    col_perm: Vec<usize>,
    col_inv: Vec<usize>,
    /// Whether the factors hold a usable factorization of the last matrix.
    ok: bool,
    work: Vec<f64>,
    solve_work: RefCell<Vec<f64>>,
    stack: MemBuffer,
    /// Factorizations with fresh pivoting, and those that reused the pivots.
    pub full: usize,
    pub refactored: usize,
}

impl RefactorLu {
    /// Analyse the pattern (COLAMD column order).
    pub fn new(sym: SymbolicSparseColMatRef<'_, usize>) -> Self {
        Self::with_order(sym, ColumnOrder::default())
    }

    /// Analyse the pattern in the column order `order`.
    pub fn with_order(sym: SymbolicSparseColMatRef<'_, usize>, order: ColumnOrder) -> Self {
        let n = sym.ncols();
        let (col_perm, col_inv) = order::column_order(sym, order);
        Self {
            pattern: Arc::default(),
            values: LuValues::default(),
            col_perm,
            col_inv,
            ok: false,
            work: vec![0.0; n],
            solve_work: RefCell::new(vec![0.0; n]),
            stack: MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n)),
            full: 0,
            refactored: 0,
        }
    }

    /// Factor `a` (the pattern given to [`RefactorLu::new`]): reuse the pivots when there
    /// are any and they hold.
    pub fn factor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), Singular> {
        if self.ok && refactor(&self.pattern, &mut self.values, &mut self.work, a) {
            self.refactored += 1;
            return Ok(());
        }
        self.full += 1;
        let q = PermRef::new_checked(&self.col_perm, &self.col_inv, a.ncols());
        self.ok = match full_factor(a, q, &mut self.stack) {
            Some((pattern, values)) => {
                self.pattern = Arc::new(pattern);
                self.values = values;
                true
            }
            None => false,
        };
        if self.ok {
            Ok(())
        } else {
            Err(Singular)
        }
    }

    /// `x <- A^-1 x`.
    pub fn solve(&self, x: &mut [f64]) -> Result<(), Singular> {
        if !self.ok {
            return Err(Singular);
        }
        solve_with(
            &self.pattern,
            &self.values,
            x,
            &mut self.solve_work.borrow_mut(),
        );
        Ok(())
    }

    /// `X <- A^-1 X` for the `k` columns of `x` (column-major); `work` is resized to `n k`.
    /// One sweep over the factors serves every column (the dense monodromy's `n` columns).
    pub fn solve_columns(
        &self,
        x: &mut [f64],
        k: usize,
        work: &mut Vec<f64>,
    ) -> Result<(), Singular> {
        if !self.ok {
            return Err(Singular);
        }
        solve_many(&self.pattern, &self.values, x, k, work);
        Ok(())
    }

    /// Entries of `L` and `U` (their diagonals included) of the current factorization: the
    /// fill is this against the matrix's entries.
    pub fn factor_entries(&self) -> usize {
        self.pattern.l_idx.len() + self.pattern.u_idx.len()
    }

    /// The current factorization, kept.
    pub fn snapshot(&self) -> Result<LuSnapshot, Singular> {
        if !self.ok {
            return Err(Singular);
        }
        Ok(LuSnapshot {
            pattern: Arc::clone(&self.pattern),
            values: self.values.clone(),
        })
    }
}

/// Partial pivoting from scratch (faer), the factors copied out. `None` when the matrix is
/// singular.
fn full_factor(
    a: SparseColMatRef<'_, usize, f64>,
    q: PermRef<'_, usize>,
    stack: &mut MemBuffer,
) -> Option<(LuPattern, LuValues)> {
    let n = a.ncols();
    let mut p = LuPattern {
        row_perm: vec![0; n],
        row_inv: vec![0; n],
        col_perm: q.arrays().0.to_vec(),
        ..Default::default()
    };
    let mut lu = SimplicialLu::<usize, f64>::new();
    factorize_simplicial_numeric_lu(
        &mut p.row_perm,
        &mut p.row_inv,
        &mut lu,
        a,
        q,
        MemStack::new(stack),
    )
    .ok()?;
    let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
    p.l_ptr = l.symbolic().col_ptr().to_vec();
    p.l_idx = l.symbolic().row_idx().to_vec();
    p.u_ptr = u.symbolic().col_ptr().to_vec();
    p.u_idx = u.symbolic().row_idx().to_vec();
    let diag = |j: usize| p.u_ptr[j + 1] - 1;
    let regular = (0..n).all(|j| {
        let d = u.val()[diag(j)];
        d.is_finite() && d != 0.0 && p.u_idx[diag(j)] == j
    });
    let values = LuValues {
        l: l.val().to_vec(),
        u: u.val().to_vec(),
        u_inv_diag: (0..n).map(|j| 1.0 / u.val()[diag(j)]).collect(),
    };
    regular.then_some((p, values))
}

/// Gilbert-Peierls with the kept pivots and patterns. False (the values then unusable)
/// when a pivot fails the tolerance.
fn refactor(
    p: &LuPattern,
    v: &mut LuValues,
    x: &mut [f64],
    a: SparseColMatRef<'_, usize, f64>,
) -> bool {
    let (ap, ai, av) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for (j, &c) in p.col_perm.iter().enumerate() {
        for e in ap[c]..ap[c + 1] {
            x[p.row_inv[ai[e]]] += av[e];
        }
        let last = p.u_ptr[j + 1] - 1;
        let (ui, uv) = (&p.u_idx[p.u_ptr[j]..last], &mut v.u[p.u_ptr[j]..last]);
        for (&r, u) in ui.iter().zip(uv) {
            let xr = x[r];
            x[r] = 0.0;
            *u = xr;
            let (a, b) = (p.l_ptr[r] + 1, p.l_ptr[r + 1]);
            for (&i, &l) in p.l_idx[a..b].iter().zip(&v.l[a..b]) {
                x[i] -= l * xr;
            }
        }
        let pivot = x[j];
        x[j] = 0.0;
        let below = p.l_ptr[j] + 1..p.l_ptr[j + 1];
        let largest = p.l_idx[below.clone()]
            .iter()
            .fold(0.0f64, |m, &i| m.max(x[i].abs()));
        let good = pivot.is_finite() && pivot != 0.0 && pivot.abs() > PIVOT_TOLERANCE * largest;
        v.u[last] = pivot;
        v.u_inv_diag[j] = 1.0 / pivot;
        for k in below {
            let i = p.l_idx[k];
            v.l[k] = x[i] / pivot;
            x[i] = 0.0;
        }
        if !good {
            x.fill(0.0);
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
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
            d[(0, i)] += 0.2 * s;
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
        assert_eq!((lu.full, lu.refactored), (1, 3));
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
            let mut lu = RefactorLu::with_order(a.symbolic(), order);
            lu.factor(a.as_ref()).expect("regular");
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
        let mut lu = RefactorLu::new(sparse(&build(2.0)).symbolic());
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
}
