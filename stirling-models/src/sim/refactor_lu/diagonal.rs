//! Diagonal pivots in AMD's order: the pattern [`RefactorLu`](super::RefactorLu) tries before
//! partial pivoting's.
//!
//! Partial pivoting on the Newton matrices `I - c J` of the regenerator chain leaves the
//! diagonal: a mass state's column holds 1 on the diagonal and up to 1e7 in the pressures' rows,
//! and COLAMD's order, made for any row pivoting, then leaves a fill of about 2.6x. Pivoting on
//! that 1 is stable all the same, because the mass state's row holds only entries of 1e-8 (the
//! multipliers are large, the updates they make are not): the refactorization's pivot test
//! accepts a pivot that dominates either its column or its row (`refactor`). This module gives
//! the pattern: AMD on `A + A^T` (made for diagonal pivots) and the patterns of `L` and `U` of a
//! factorization that keeps the diagonal. The values are the caller's, and the pivot test
//! decides whether the pattern is kept.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::simplicial::{
    factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch, SimplicialLu,
};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef, Triplet};

use super::order::{column_order, ColumnOrder};
use super::LuPattern;

/// The diagonal in the symbolic factorization: large enough that
/// partial pivoting never leaves it (every other entry is 1).
const DOMINANT: f64 = 1e150;

/// The pattern of diagonal pivots of `a` in AMD's order on `A + A^T` (the matrix's own order if
/// AMD fails); `None` when a diagonal entry is missing from the pattern.
pub(super) fn diagonal_pattern(a: SymbolicSparseColMatRef<'_, usize>) -> Option<LuPattern> {
    let n = a.ncols();
    let (cp, ri) = (a.col_ptr(), a.row_idx());
    if (0..n).any(|k| !ri[cp[k]..cp[k + 1]].contains(&k)) {
        return None;
    }
    let (fwd, inv) = column_order(a, ColumnOrder::Amd);
    // C = P A P^T with the diagonal dominant, factored in its own (identity) order
    let mut trip = Vec::with_capacity(ri.len());
    for k in 0..n {
        trip.extend(ri[cp[k]..cp[k + 1]].iter().map(|&i| {
            let v = if i == k { DOMINANT } else { 1.0 };
            Triplet::new(inv[i], inv[k], v)
        }));
    }
    let c = SparseColMat::try_new_from_triplets(n, n, &trip).ok()?;
    let mut p = symbolic_factor(c.as_ref())?;
    (p.row_perm, p.row_inv, p.col_perm) = (fwd.clone(), inv, fwd);
    Some(p)
}

/// The patterns of `L` and `U` of `c` factored in its own order with diagonal pivots (`c`'s
/// diagonal dominates, so partial pivoting keeps it; checked). Permutations left empty.
fn symbolic_factor(c: SparseColMatRef<'_, usize, f64>) -> Option<LuPattern> {
    let n = c.ncols();
    let id: Vec<usize> = (0..n).collect();
    let q = PermRef::new_checked(&id, &id, n);
    let (mut rp, mut ri) = (vec![0usize; n], vec![0usize; n]);
    let mut lu = SimplicialLu::<usize, f64>::new();
    let mut mem = MemBuffer::new(factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n));
    factorize_simplicial_numeric_lu(&mut rp, &mut ri, &mut lu, c, q, MemStack::new(&mut mem))
        .ok()?;
    if rp != id {
        return None;
    }
    let mut p = LuPattern::default();
    p.copy_factors(&lu);
    let diag_last = (0..n).all(|j| p.u_idx[p.u_ptr[j + 1] - 1] == j);
    let diag_first = (0..n).all(|j| p.l_idx[p.l_ptr[j]] == j);
    (diag_last && diag_first).then_some(p)
}
