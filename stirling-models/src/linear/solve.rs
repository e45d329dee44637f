//! Dense real linear solves `A x = b` by LU with partial pivoting (faer: blocked and
//! parallel-friendly, so the 2007-state systems of `nsection` at n = 1000 stay affordable).
//! `None` when the result is not finite (a singular matrix).

use faer::linalg::solvers::Solve;
use faer::Mat;
use nalgebra::{DMatrix, DVector};

/// Solve `a x = b`.
pub fn solve(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<DVector<f64>> {
    let n = a.nrows();
    let m = Mat::<f64>::from_fn(n, n, |i, j| a[(i, j)]);
    let rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
    let x = m.partial_piv_lu().solve(&rhs);
    let x = DVector::from_fn(n, |i, _| x[(i, 0)]);
    x.iter().all(|v| v.is_finite()).then_some(x)
}
