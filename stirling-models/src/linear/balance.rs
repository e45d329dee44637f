//! Diagonal balancing (Parlett-Reinsch, radix 2): `A_b = D^-1 A D` with row and column
//! norms of similar size, so that pressures (~1e5 Pa), masses (~1e-4 kg) and positions
//! (~1e-3 m) do not cost the eigenvalue and frequency-response computations their accuracy.
//! Powers of two keep the similarity exact in floating point.

use nalgebra::DMatrix;

/// The balanced matrix and the scaling `d` (`A_b = D^-1 A D`, `D = diag(d)`).
pub fn balance(a: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let n = a.nrows();
    let mut b = a.clone();
    let mut d = vec![1.0; n];
    let (radix, sqr) = (2.0f64, 4.0f64);
    for _sweep in 0..200 {
        let mut done = true;
        for i in 0..n {
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += b[(j, i)].abs();
                    r += b[(i, j)].abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let s = c + r;
            let mut f = 1.0;
            let mut g = r / radix;
            while c < g {
                f *= radix;
                c *= sqr;
            }
            g = r * radix;
            while c > g {
                f /= radix;
                c /= sqr;
            }
            if (c + r) / f < 0.95 * s {
                done = false;
                d[i] *= f;
                b.row_mut(i).scale_mut(1.0 / f);
                b.column_mut(i).scale_mut(f);
            }
        }
        if done {
            break;
        }
    }
    (b, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn similarity_keeps_the_trace_and_evens_the_norms() {
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1e6, 1e-6, 2.0]);
        let (b, d) = balance(&a);
        assert!((b.trace() - a.trace()).abs() < 1e-12);
        assert!((b[(0, 1)].abs() / b[(1, 0)].abs()).log2().abs() <= 2.0);
        assert!((b[(0, 1)] - a[(0, 1)] * d[1] / d[0]).abs() < 1e-9);
    }
}
