//! The column order of the first factorization (the refactorizations keep it): COLAMD on `A`
//! (faer's default for an unsymmetric LU, and ours), AMD on the pattern of `A + A^T` (KLU's
//! default), or the matrix's own order.
//!
//! Why COLAMD: it orders for any row pivoting, and partial pivoting on the stiff Newton
//! matrices `I - c J` of the regenerator chain leaves the diagonal often (a mass state's column
//! holds 1 on the diagonal and up to 1e11 in the pressures' rows). AMD's order, made for
//! diagonal pivots, then fills 8x (n = 100) to 76x (n = 1000) more than COLAMD's, and a banded
//! order along the sections ([`ColumnOrder::Banded`]) only 3 % less. Measured by
//! `examples/lu_fill.rs` (docs/performance.md, "The Newton matrix's fill").

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::linalg::lu::factorize_symbolic_lu;
use faer::sparse::SymbolicSparseColMatRef;

/// Which fill-reducing column order the factorization (partial pivoting) uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColumnOrder {
    /// COLAMD on `A`.
    #[default]
    Colamd,
    /// AMD on the pattern of `A + A^T`.
    Amd,
    /// The matrix's own order.
    Natural,
    /// Reverse Cuthill-McKee on the pattern of `A + A^T` (a banded order, along the sections
    /// of a chain).
    Banded,
}

impl ColumnOrder {
    /// Every order, the default first.
    pub const ALL: [ColumnOrder; 4] = [
        ColumnOrder::Colamd,
        ColumnOrder::Banded,
        ColumnOrder::Amd,
        ColumnOrder::Natural,
    ];
}

/// The permutation `(forward, inverse)` for `sym` in `order`; the natural order when the
/// ordering fails (it only reorders, so any permutation is correct).
pub(super) fn column_order(
    sym: SymbolicSparseColMatRef<'_, usize>,
    order: ColumnOrder,
) -> (Vec<usize>, Vec<usize>) {
    let n = sym.ncols();
    let natural = || ((0..n).collect(), (0..n).collect());
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let ok = match order {
        ColumnOrder::Natural => return natural(),
        ColumnOrder::Banded => return super::rcm::order(sym),
        ColumnOrder::Amd => {
            let nnz = sym.compute_nnz();
            let mut mem = MemBuffer::new(amd::order_maybe_unsorted_scratch::<usize>(n, nnz));
            amd::order_maybe_unsorted(
                &mut fwd,
                &mut inv,
                sym,
                Default::default(),
                MemStack::new(&mut mem),
            )
            .is_ok()
        }
        ColumnOrder::Colamd => match factorize_symbolic_lu(sym, Default::default()) {
            Ok(s) => {
                let (f, i) = s.col_perm().arrays();
                (fwd, inv) = (f.to_vec(), i.to_vec());
                true
            }
            Err(_) => false,
        },
    };
    if ok {
        (fwd, inv)
    } else {
        natural()
    }
}
