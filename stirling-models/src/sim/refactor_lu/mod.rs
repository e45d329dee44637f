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
//! factorization to factorization); a pivot that fails the test below, or is not finite, makes
//! the factorization try the diagonal pattern, then start over with fresh partial pivoting. A
//! matrix singular even then is an error at the solve, which the integrator treats as a failed
//! step.
//!
//! The factors of one matrix can be kept ([`LuSnapshot`](crate::sim::refactor_lu::LuSnapshot): the
//! values only, the pattern is shared while the pivots hold), which is how the tangent route stores
//! one factorization per step of a period at half the memory of faer's factors.
//!
//! Before partial pivoting the factorization tries diagonal pivots in AMD's order (`diagonal`):
//! on `nsection`'s Newton matrices that pattern holds about a third fewer entries. Whichever
//! pattern is used, it is kept while its pivots pass the test: a pivot not smaller than
//! [`PIVOT_TOLERANCE`](crate::sim::refactor_lu::PIVOT_TOLERANCE) times the largest entry below it
//! in its column *or* right of it in its row (either bounds the growth of the entries a step
//! makes by the tolerance's inverse: the column test bounds the multipliers, the row test the
//! pivot row).
//!
//! Why our own: neither faer nor diffsol has a refactorization with a fixed pivot sequence,
//! and KLU itself is C (SuiteSparse) that the project does not otherwise need.

mod diagonal;
mod order;
mod rcm;
mod refactor;
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
use refactor::{refactor, Scratch};
use solve::{solve_many, solve_with};

/// A kept pivot smaller than this times both the largest entry below it and the largest right
/// of it starts a new pivoting.
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

impl LuPattern {
    /// The patterns of `L` and `U` copied out of faer's factors (the permutations untouched).
    fn copy_factors(&mut self, lu: &SimplicialLu<usize, f64>) {
        let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
        self.l_ptr = l.symbolic().col_ptr().to_vec();
        self.l_idx = l.symbolic().row_idx().to_vec();
        self.u_ptr = u.symbolic().col_ptr().to_vec();
        self.u_idx = u.symbolic().row_idx().to_vec();
    }
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
    work: Scratch,
    solve_work: RefCell<Vec<f64>>,
    stack: MemBuffer,
    /// Diagonal pivots in AMD's order (`diagonal`), when the pattern has them: tried before
    /// every fresh partial pivoting; `None` also when [`RefactorLu::partial_pivoting_only`].
    diagonal: Option<Arc<LuPattern>>,
    /// Factorizations with fresh partial pivoting, and those on a pattern given beforehand
    /// (the pivots kept from the last factorization, or the diagonal pattern).
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
            work: Scratch::new(n),
            solve_work: RefCell::new(vec![0.0; n]),
            stack: MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n)),
            diagonal: diagonal::diagonal_pattern(sym).map(Arc::new),
            full: 0,
            refactored: 0,
        }
    }

    /// Partial pivoting only, no diagonal pattern tried (the fill's baseline).
    pub fn partial_pivoting_only(mut self) -> Self {
        self.diagonal = None;
        self
    }

    /// Whether the current factors pivot on the diagonal in AMD's order.
    pub fn on_diagonal(&self) -> bool {
        self.ok && self.is_diagonal(&self.pattern)
    }

    fn is_diagonal(&self, p: &Arc<LuPattern>) -> bool {
        self.diagonal.as_ref().is_some_and(|d| Arc::ptr_eq(d, p))
    }

    /// Factor `a` (the pattern given to [`RefactorLu::new`]): reuse the pivots when there
    /// are any and they hold, else the diagonal's when they hold, else pivot afresh.
    pub fn factor(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), Singular> {
        let tried = self.ok;
        if self.ok && refactor(&self.pattern, &mut self.values, &mut self.work, a) {
            self.refactored += 1;
            return Ok(());
        }
        let diagonal_failed = tried && self.is_diagonal(&self.pattern);
        if !diagonal_failed && self.try_diagonal(a) {
            self.refactored += 1;
            return Ok(());
        }
        self.full += 1;
        self.pivot_afresh(a)
    }

    /// Refactor `a` on the diagonal pattern, kept when its pivots hold.
    fn try_diagonal(&mut self, a: SparseColMatRef<'_, usize, f64>) -> bool {
        let Some(d) = self.diagonal.clone() else {
            return false;
        };
        let mut v = LuValues {
            l: vec![1.0; d.l_idx.len()],
            u: vec![0.0; d.u_idx.len()],
            u_inv_diag: vec![0.0; d.row_perm.len()],
        };
        if !refactor(&d, &mut v, &mut self.work, a) {
            self.ok = false;
            return false;
        }
        (self.pattern, self.values, self.ok) = (d, v, true);
        true
    }

    /// Partial pivoting from scratch.
    fn pivot_afresh(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<(), Singular> {
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
    p.copy_factors(&lu);
    let (l, u) = (lu.l_factor_unsorted(), lu.u_factor_unsorted());
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

#[cfg(test)]
mod tests;
