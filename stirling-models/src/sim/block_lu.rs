//! A linear solver for block-diagonal Newton matrices whose blocks repeat: the
//! forward-sensitivity systems of the fit (state plus one column per fitted variable) hand
//! the solver `diag(I - cJ, ..., I - cJ)`, one copy of the state block per column.
//!
//! Why our own: faer's sparse LU factors every block of that matrix anew (on the `p, x, y`
//! diagnosis it took a third of the run), and diffsol's dense LU factors the whole `(k + 1) nz`
//! matrix. This solver reads the pattern once ([`block_size`](crate::sim::block_lu::block_size)),
//! factors each *distinct* block once per Newton-matrix update (dense LU, nalgebra) and solves
//! every block with the factorization of the block it equals, so `k + 1` equal blocks cost one `nz
//! x nz` factorization (the staggered corrector of CVODES' sensitivities). Blocks are compared by
//! value, so a block-diagonal matrix whose blocks differ is still solved exactly; a pattern that is
//! not block-diagonal with equal block sizes falls back to the refactoring sparse LU
//! ([`crate::sim::refactor_lu`]).

use diffsol::{FaerContext, FaerSparseMat, FaerVec, LaError, Matrix, MatrixCommon, Vector};
use diffsol_la::error::LinearSolverError;
use diffsol_la::{LinearOp, LinearSolver};
use faer::sparse::SymbolicSparseColMatRef;
use nalgebra::{DMatrix, DMatrixViewMut, LU};

use super::refactor_lu::RefactorLu;

/// The block solver (see the module doc).
#[derive(Default)]
pub struct BlockLu {
    a: Option<FaerSparseMat<f64>>,
    /// The block size, when the pattern is block-diagonal with equal blocks.
    block: usize,
    /// The distinct factorizations, and which one each block uses.
    lus: Vec<LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    which: Vec<usize>,
    fallback: Option<RefactorLu>,
}

/// The size `b` of the diagonal blocks when the pattern is block-diagonal with blocks of
/// equal size and equal pattern (`None` otherwise, or for a single block).
pub fn block_size(sym: SymbolicSparseColMatRef<'_, usize>) -> Option<usize> {
    let (n, cp, ri) = (sym.ncols(), sym.col_ptr(), sym.row_idx());
    if n == 0 || sym.nrows() != n {
        return None;
    }
    // the first block ends where no column before it reaches below it
    let mut b = 1;
    let mut c = 0;
    while c < b {
        let last = ri[cp[c]..cp[c + 1]].iter().copied().max().unwrap_or(c);
        b = b.max(last + 1).max(c + 1);
        c += 1;
    }
    if b >= n || n % b != 0 {
        return None;
    }
    for c in 0..n {
        let (k, c0) = (c / b, c % b);
        let rows = &ri[cp[c]..cp[c + 1]];
        let first = &ri[cp[c0]..cp[c0 + 1]];
        if rows.len() != first.len() || rows.iter().zip(first).any(|(r, f)| *r != f + k * b) {
            return None;
        }
    }
    Some(b)
}

impl BlockLu {
    /// Factor the distinct blocks of the current matrix.
    fn factor(&mut self) {
        let a = self.a.as_ref().expect("the pattern is set first");
        let m = &a.inner()[0];
        let (b, n) = (self.block, m.ncols());
        let (cp, ri, v) = (m.symbolic().col_ptr(), m.symbolic().row_idx(), m.val());
        let block_vals = |k: usize| &v[cp[k * b]..cp[(k + 1) * b]];
        self.lus.clear();
        self.which.clear();
        let mut firsts: Vec<usize> = Vec::new();
        for k in 0..n / b {
            if let Some(j) = firsts.iter().position(|&f| block_vals(f) == block_vals(k)) {
                self.which.push(j);
                continue;
            }
            let mut d = DMatrix::zeros(b, b);
            for c in 0..b {
                let col = k * b + c;
                for e in cp[col]..cp[col + 1] {
                    d[(ri[e] - k * b, c)] = v[e];
                }
            }
            self.which.push(self.lus.len());
            firsts.push(k);
            self.lus.push(d.lu());
        }
    }
}

impl LinearSolver<FaerSparseMat<f64>> for BlockLu {
    fn set_linearisation<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let a = self.a.as_mut().expect("the pattern is set first");
        op.matrix_inplace(a);
        if let Some(f) = self.fallback.as_mut() {
            // a singular matrix is reported by the solve (a failed step)
            let _ = f.factor(a.inner()[0].as_ref());
            return;
        }
        self.factor();
    }

    fn solve_in_place(&self, x: &mut FaerVec<f64>) -> Result<(), LaError> {
        if let Some(f) = self.fallback.as_ref() {
            return f
                .solve(x.inner_mut().col_as_slice_mut(0))
                .map_err(|_| LinearSolverError::LuSolveFailed.into());
        }
        if self.which.is_empty() {
            return Err(LinearSolverError::LuNotInitialized.into());
        }
        let b = self.block;
        let xs = x.inner_mut().col_as_slice_mut(0);
        let ok = if self.lus.len() == 1 {
            // every block the same: one solve with the blocks as right-hand-side columns
            let nb = self.which.len();
            self.lus[0].solve_mut(&mut DMatrixViewMut::from_slice(xs, b, nb))
        } else {
            self.which.iter().enumerate().all(|(k, &j)| {
                let seg = &mut xs[k * b..(k + 1) * b];
                self.lus[j].solve_mut(&mut DMatrixViewMut::from_slice(seg, b, 1))
            })
        };
        if ok {
            Ok(())
        } else {
            Err(LinearSolverError::LuSolveFailed.into())
        }
    }

    fn solve_transpose_in_place(&self, _x: &mut FaerVec<f64>) -> Result<(), LaError> {
        Err(LinearSolverError::Other("the block LU has no transposed solve".into()).into())
    }

    fn set_sparsity<
        C: LinearOp<T = f64, V = FaerVec<f64>, M = FaerSparseMat<f64>, C = FaerContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let a =
            FaerSparseMat::new_from_sparsity(op.nrows(), op.ncols(), op.sparsity(), *op.context());
        match block_size(a.inner()[0].symbolic()) {
            Some(b) => {
                self.block = b;
                self.fallback = None;
            }
            None => self.fallback = Some(RefactorLu::new(a.inner()[0].symbolic())),
        }
        self.a = Some(a);
        self.lus.clear();
        self.which.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use diffsol::{FaerVec, Vector};

    /// A fixed sparse matrix as a linear operator.
    struct Fixed(FaerSparseMat<f64>);

    impl LinearOp for Fixed {
        type T = f64;
        type V = FaerVec<f64>;
        type M = FaerSparseMat<f64>;
        type C = FaerContext;
        fn nrows(&self) -> usize {
            self.0.nrows()
        }
        fn ncols(&self) -> usize {
            self.0.ncols()
        }
        fn context(&self) -> &FaerContext {
            self.0.context()
        }
        fn matrix_inplace(&self, y: &mut FaerSparseMat<f64>) {
            y.copy_from(&self.0);
        }
        fn sparsity(&self) -> Option<faer::sparse::SymbolicSparseColMat<usize>> {
            Some(self.0.inner()[0].symbolic().to_owned().expect("pattern"))
        }
    }

    /// `blocks` dense blocks of size `b` on the diagonal (plus `extra` off-block entries).
    fn matrix(blocks: &[Vec<f64>], b: usize, extra: &[(usize, usize, f64)]) -> Fixed {
        let (mut idx, mut val) = (Vec::new(), Vec::new());
        for (k, blk) in blocks.iter().enumerate() {
            for c in 0..b {
                for r in 0..b {
                    if blk[r + c * b] != 0.0 || r == c {
                        idx.push((k * b + r, k * b + c));
                        val.push(blk[r + c * b]);
                    }
                }
            }
        }
        for &(r, c, v) in extra {
            idx.push((r, c));
            val.push(v);
        }
        let n = blocks.len() * b;
        Fixed(FaerSparseMat::try_from_triplets(n, n, idx, val, FaerContext::default()).unwrap())
    }

    /// Solve with the block LU and compare `A x` with `b`.
    fn check(op: &Fixed) -> BlockLu {
        let n = op.nrows();
        let mut s = BlockLu::default();
        s.set_sparsity(op);
        s.set_linearisation(op);
        let rhs: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64 * 0.7).sin()).collect();
        let mut x = FaerVec::from_vec(rhs.clone(), FaerContext::default());
        s.solve_in_place(&mut x).unwrap();
        let mut ax = FaerVec::zeros(n, FaerContext::default());
        op.0.gemv(1.0, &x, 0.0, &mut ax);
        for i in 0..n {
            assert!(
                (ax[i] - rhs[i]).abs() < 1e-12,
                "row {i}: {} vs {}",
                ax[i],
                rhs[i]
            );
        }
        s
    }

    const B0: [f64; 9] = [4.0, 1.0, 0.0, -2.0, 5.0, 1.0, 0.5, 0.0, 3.0];

    #[test]
    fn equal_blocks_are_factored_once() {
        let s = check(&matrix(&vec![B0.to_vec(); 4], 3, &[]));
        assert_eq!((s.block, s.lus.len(), s.which.len()), (3, 1, 4));
    }

    #[test]
    fn different_blocks_are_factored_each() {
        let mut b1 = B0.to_vec();
        b1[0] = 7.0;
        let s = check(&matrix(&[B0.to_vec(), b1, B0.to_vec()], 3, &[]));
        assert_eq!((s.lus.len(), s.which.clone()), (2, vec![0, 1, 0]));
    }

    #[test]
    fn a_coupled_pattern_falls_back_to_the_sparse_lu() {
        let s = check(&matrix(&vec![B0.to_vec(); 2], 3, &[(4, 1, 0.3)]));
        assert!(s.fallback.is_some());
    }

    #[test]
    fn block_size_reads_the_pattern() {
        let op = matrix(&vec![B0.to_vec(); 5], 3, &[]);
        assert_eq!(block_size(op.0.inner()[0].symbolic()), Some(3));
        // a single block is not worth the split
        let one = matrix(&[B0.to_vec()], 3, &[]);
        assert_eq!(block_size(one.0.inner()[0].symbolic()), None);
    }
}
