//! The diagonal of the Gauss-Newton covariance of a least-squares fit, from the SVD of its
//! Jacobian: the intervals of the joint fits and the fixed point's step size use it.

/// The diagonal of the Gauss-Newton covariance `(J^T J)^-1` over the columns `free` of `j`
/// (unit residual variance), from the SVD of `J` (squaring `J` first loses the small singular
/// values); directions below 1e-12 of the largest singular value count as zero.
pub fn covariance_diagonal(j: &nalgebra::DMatrix<f64>, free: &[usize]) -> Option<Vec<f64>> {
    let svd = j.select_columns(free).svd(false, true);
    let vt = svd.v_t?;
    let smax = svd.singular_values.max();
    let inv2 = svd
        .singular_values
        .map(|v| if v > 1e-12 * smax { 1.0 / (v * v) } else { 0.0 });
    Some(
        (0..free.len())
            .map(|k| (0..inv2.len()).map(|m| vt[(m, k)].powi(2) * inv2[m]).sum())
            .collect(),
    )
}
