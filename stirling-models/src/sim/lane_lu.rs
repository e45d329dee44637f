//! A dense LU for small Newton matrices whose right-hand sides come in many lanes (the sensitivity
//! columns of [`crate::sim::sens`], `n` entries a lane, stored one after the other).
//!
//! Why not diffsol's `NalgebraLU`: it solves lane by lane through nalgebra's generic
//! triangular solves, which for the few states of a driven subsystem cost more than the
//! arithmetic (17 % of a fit). Here the factorization (partial pivoting, the same elimination
//! as nalgebra's) is kept as plain column-major numbers and every lane is solved by two tight
//! substitution loops.

use diffsol::{LaError, Matrix, MatrixCommon, NalgebraContext, NalgebraMat, NalgebraVec, Vector};
use diffsol_la::error::LinearSolverError;
use diffsol_la::{LinearOp, LinearSolver};

/// The factorization `P A = L U` of an `n x n` matrix (see the module doc).
#[derive(Default)]
pub struct LaneLu {
    a: Option<NalgebraMat<f64>>,
    n: usize,
    /// `L` (unit diagonal, below) and `U` (on and above), column-major.
    lu: Vec<f64>,
    /// Row swaps in elimination order.
    piv: Vec<(usize, usize)>,
    singular: bool,
    /// `A^-1`, column-major, when `n <= INV_MAX` (see [`LaneLu::solve_lane_inv`]).
    inv: Vec<f64>,
}

/// Up to this size a lane is solved by the explicit inverse.
const INV_MAX: usize = 32;

impl LaneLu {
    /// Factor `self.lu` in place (`n x n`, column-major).
    fn factor(&mut self) {
        let (n, a) = (self.n, &mut self.lu);
        self.piv.clear();
        self.singular = false;
        for i in 0..n {
            let p = (i..n)
                .max_by(|&r, &s| a[r + i * n].abs().total_cmp(&a[s + i * n].abs()))
                .unwrap_or(i);
            if a[p + i * n] == 0.0 {
                self.singular = true;
                continue;
            }
            if p != i {
                self.piv.push((i, p));
                for c in 0..n {
                    a.swap(i + c * n, p + c * n);
                }
            }
            let d = a[i + i * n];
            for r in i + 1..n {
                a[r + i * n] /= d;
            }
            for c in i + 1..n {
                let u = a[i + c * n];
                if u != 0.0 {
                    for r in i + 1..n {
                        a[r + c * n] -= a[r + i * n] * u;
                    }
                }
            }
        }
    }

    /// Form `A^-1` from the factors (one lane per unit vector). A step's Newton matrix is
    /// factored once and solves every lane of a few sensitivity corrections: a product with
    /// the inverse is one branch-free column sweep a lane, where the substitutions swap, test
    /// and loop over triangles (the `p, x, y` diagnosis of docs/diagnosis.md ran 7-10 % faster
    /// in CPU time, the inverse's own cost included).
    fn invert(&mut self) {
        let n = self.n;
        self.inv.clear();
        if self.singular || n > INV_MAX {
            return;
        }
        self.inv.resize(n * n, 0.0);
        let mut inv = std::mem::take(&mut self.inv);
        for c in 0..n {
            inv[c + c * n] = 1.0;
            self.solve_lane(&mut inv[c * n..(c + 1) * n]);
        }
        self.inv = inv;
    }

    /// Solve one lane by the inverse: `x = A^-1 x`, one column sweep.
    fn solve_lane_inv(&self, x: &mut [f64]) {
        let n = self.n;
        let mut y = [0.0; INV_MAX];
        let y = &mut y[..n];
        for (c, &v) in x.iter().enumerate() {
            let col = &self.inv[c * n..(c + 1) * n];
            y.iter_mut().zip(col).for_each(|(a, b)| *a += b * v);
        }
        x.copy_from_slice(y);
    }

    /// Solve one lane `x` (length `n`) in place.
    fn solve_lane(&self, x: &mut [f64]) {
        let (n, a) = (self.n, &self.lu);
        for &(i, p) in &self.piv {
            x.swap(i, p);
        }
        for c in 0..n {
            let v = x[c];
            if v != 0.0 {
                for r in c + 1..n {
                    x[r] -= a[r + c * n] * v;
                }
            }
        }
        for c in (0..n).rev() {
            x[c] /= a[c + c * n];
            let v = x[c];
            for r in 0..c {
                x[r] -= a[r + c * n] * v;
            }
        }
    }
}

impl LinearSolver<NalgebraMat<f64>> for LaneLu {
    fn set_linearisation<
        C: LinearOp<T = f64, V = NalgebraVec<f64>, M = NalgebraMat<f64>, C = NalgebraContext>,
    >(
        &mut self,
        op: &C,
    ) {
        let a = self.a.as_mut().expect("the matrix is set first");
        op.matrix_inplace(a);
        self.lu.clear();
        self.lu.extend_from_slice(a.inner().as_slice());
        self.factor();
        self.invert();
    }

    fn solve_in_place(&self, x: &mut NalgebraVec<f64>) -> Result<(), LaError> {
        if self.lu.is_empty() && self.n > 0 {
            return Err(LinearSolverError::LuNotInitialized.into());
        }
        if self.singular {
            return Err(LinearSolverError::LuSolveFailed.into());
        }
        let xs = x.inner_mut().as_mut_slice();
        if self.inv.is_empty() {
            for lane in xs.chunks_mut(self.n.max(1)) {
                self.solve_lane(lane);
            }
        } else {
            for lane in xs.chunks_mut(self.n) {
                self.solve_lane_inv(lane);
            }
        }
        Ok(())
    }

    fn solve_transpose_in_place(&self, _x: &mut NalgebraVec<f64>) -> Result<(), LaError> {
        Err(LinearSolverError::Other("the lane LU has no transposed solve".into()).into())
    }

    fn set_sparsity<
        C: LinearOp<T = f64, V = NalgebraVec<f64>, M = NalgebraMat<f64>, C = NalgebraContext>,
    >(
        &mut self,
        op: &C,
    ) {
        self.n = op.nrows();
        self.a = Some(NalgebraMat::new_from_sparsity(
            op.nrows(),
            op.ncols(),
            None,
            *op.context(),
        ));
        self.lu.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use diffsol::VectorCommon;

    /// A fixed dense matrix as a linear operator.
    struct Fixed(NalgebraMat<f64>);

    impl LinearOp for Fixed {
        type T = f64;
        type V = NalgebraVec<f64>;
        type M = NalgebraMat<f64>;
        type C = NalgebraContext;
        fn nrows(&self) -> usize {
            self.0.nrows()
        }
        fn ncols(&self) -> usize {
            self.0.ncols()
        }
        fn context(&self) -> &NalgebraContext {
            self.0.context()
        }
        fn matrix_inplace(&self, y: &mut NalgebraMat<f64>) {
            y.copy_from(&self.0);
        }
    }

    /// `A` (column-major) as an operator, factored.
    fn factored(m: &nalgebra::DMatrix<f64>) -> LaneLu {
        let n = m.nrows();
        let mut a: NalgebraMat<f64> =
            NalgebraMat::new_from_sparsity(n, n, None, NalgebraContext::default());
        a.inner_mut().copy_from(m);
        let op = Fixed(a);
        let mut s = LaneLu::default();
        s.set_sparsity(&op);
        s.set_linearisation(&op);
        s
    }

    /// Above [`INV_MAX`] the lanes are solved by the substitutions: the same answers.
    #[test]
    fn large_matrices_are_solved_by_the_factors() {
        let n = INV_MAX + 8;
        let m = nalgebra::DMatrix::from_fn(n, n, |r, c| {
            let v = ((r * 7 + c * 13) % 11) as f64 - 5.0;
            if r == c {
                v + 3.0 * n as f64
            } else {
                v
            }
        });
        let s = factored(&m);
        assert!(s.inv.is_empty(), "no inverse above INV_MAX");
        let rhs: Vec<f64> = (0..2 * n).map(|i| (i as f64 * 0.3).cos()).collect();
        let mut x = NalgebraVec::from_vec(rhs.clone(), NalgebraContext::default());
        s.solve_in_place(&mut x).unwrap();
        let xs = x.inner().as_slice();
        for l in 0..2 {
            let xl = nalgebra::DVector::from_column_slice(&xs[l * n..(l + 1) * n]);
            let ax = &m * xl;
            for i in 0..n {
                assert!((ax[i] - rhs[l * n + i]).abs() < 1e-12, "lane {l} row {i}");
            }
        }
    }

    /// A singular matrix is an error, not a wrong answer.
    #[test]
    fn a_singular_matrix_is_refused() {
        let m = nalgebra::DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 2.0, 4.0]);
        let s = factored(&m);
        let mut x = NalgebraVec::from_vec(vec![1.0, 1.0], NalgebraContext::default());
        assert!(s.solve_in_place(&mut x).is_err());
    }

    #[test]
    fn solves_every_lane_with_pivoting() {
        // a zero (0, 0) entry forces a row swap
        let n = 4;
        let m = nalgebra::DMatrix::from_row_slice(
            n,
            n,
            &[
                0.0, 2.0, 1.0, 0.5, 3.0, 1.0, 0.0, 2.0, 1.0, 4.0, 5.0, 1.0, 2.0, 0.0, 1.0, 6.0,
            ],
        );
        let mut a: NalgebraMat<f64> =
            NalgebraMat::new_from_sparsity(n, n, None, NalgebraContext::default());
        a.inner_mut().copy_from(&m);
        let op = Fixed(a);
        let mut s = LaneLu::default();
        s.set_sparsity(&op);
        s.set_linearisation(&op);
        let lanes = 3;
        let rhs: Vec<f64> = (0..n * lanes)
            .map(|i| 1.0 + (i as f64 * 0.7).sin())
            .collect();
        let mut x = NalgebraVec::from_vec(rhs.clone(), NalgebraContext::default());
        s.solve_in_place(&mut x).unwrap();
        let xs = x.inner().as_slice();
        for l in 0..lanes {
            let xl = nalgebra::DVector::from_column_slice(&xs[l * n..(l + 1) * n]);
            let ax = &m * xl;
            for i in 0..n {
                assert!((ax[i] - rhs[l * n + i]).abs() < 1e-12, "lane {l} row {i}");
            }
        }
    }
}
