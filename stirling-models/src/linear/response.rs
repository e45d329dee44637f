//! The frequency response `L(s) = K (sI - A)^-1 B` of a single-input single-output triple.
//!
//! `A` is balanced (`D^-1 A D`) and reduced once to upper Hessenberg form `H = Q' A_b Q`
//! (`O(n^3)`); each evaluation then solves the complex Hessenberg system `(sI - H) z = Q' D^-1 B`
//! by Gaussian elimination with adjacent-row pivoting (`O(n^2)`), and `L = (K D Q) z`.

use nalgebra::{Complex, DMatrix, DVector};

use super::balance::balance;

/// A prepared SISO frequency response.
#[derive(Clone, Debug)]
pub struct FrequencyResponse {
    h: DMatrix<f64>,
    b: DVector<f64>,
    k: DVector<f64>,
}

impl FrequencyResponse {
    /// Prepare `L(s) = k' (sI - a)^-1 b`.
    pub fn new(a: &DMatrix<f64>, b: &DVector<f64>, k: &DVector<f64>) -> Self {
        let (ab, d) = balance(a);
        let bb = DVector::from_iterator(b.len(), b.iter().zip(&d).map(|(v, d)| v / d));
        let kb = DVector::from_iterator(k.len(), k.iter().zip(&d).map(|(v, d)| v * d));
        let (q, h) = ab.hessenberg().unpack();
        Self {
            h,
            b: q.tr_mul(&bb),
            k: q.tr_mul(&kb),
        }
    }

    /// `L(s)`.
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        let z = solve_shifted_hessenberg(&self.h, s, &self.b);
        z.iter().zip(self.k.iter()).map(|(z, k)| z * k).sum()
    }

    /// `L(j w)`.
    pub fn at(&self, w: f64) -> Complex<f64> {
        self.eval(Complex::new(0.0, w))
    }
}

/// Solve `(s I - H) z = b` for upper Hessenberg `H`.
fn solve_shifted_hessenberg(
    h: &DMatrix<f64>,
    s: Complex<f64>,
    b: &DVector<f64>,
) -> Vec<Complex<f64>> {
    let n = h.nrows();
    // Row-major band: row i holds columns lo(i)..n, lo(i) = max(i - 1, 0).
    let lo = |i: usize| i.saturating_sub(1);
    let zero = Complex::new(0.0, 0.0);
    let mut m: Vec<Vec<Complex<f64>>> = (0..n)
        .map(|i| {
            (lo(i)..n)
                .map(|j| if i == j { s } else { zero } - h[(i, j)])
                .collect()
        })
        .collect();
    let mut r: Vec<Complex<f64>> = b.iter().map(|&v| Complex::new(v, 0.0)).collect();
    for i in 0..n.saturating_sub(1) {
        let (top, bottom) = m.split_at_mut(i + 1);
        let (ri, rn) = (&mut top[i], &mut bottom[0]);
        let (pi, pn) = (i - lo(i), i - lo(i + 1));
        if rn[pn].norm_sqr() > ri[pi].norm_sqr() {
            // Swap the tails (columns i..n) of rows i and i+1.
            for c in 0..(n - i) {
                std::mem::swap(&mut ri[pi + c], &mut rn[pn + c]);
            }
            r.swap(i, i + 1);
        }
        if ri[pi].norm_sqr() == 0.0 {
            continue;
        }
        let l = rn[pn] / ri[pi];
        rn[pn] = zero;
        for c in 1..(n - i) {
            let v = ri[pi + c];
            rn[pn + c] -= l * v;
        }
        let ri_r = r[i];
        r[i + 1] -= l * ri_r;
    }
    let mut z = vec![zero; n];
    for i in (0..n).rev() {
        let row = &m[i];
        let o = lo(i);
        let mut acc = r[i];
        for j in (i + 1)..n {
            acc -= row[j - o] * z[j];
        }
        z[i] = acc / row[i - o];
    }
    z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_a_dense_solve() {
        let a =
            DMatrix::from_row_slice(3, 3, &[-1.0, 2.0, 0.5, -3.0, -0.2, 1e3, 0.01, -1e-3, -50.0]);
        let b = DVector::from_vec(vec![0.0, 1.0, 2.0]);
        let k = DVector::from_vec(vec![1.0, -1.0, 0.3]);
        let fr = FrequencyResponse::new(&a, &b, &k);
        for w in [0.1, 3.0, 70.0] {
            let s = Complex::new(0.0, w);
            let m = DMatrix::from_fn(3, 3, |i, j| if i == j { s } else { Complex::new(0.0, 0.0) } - Complex::new(a[(i, j)], 0.0));
            let z = m.lu().solve(&b.map(|v| Complex::new(v, 0.0))).unwrap();
            let l: Complex<f64> = z.iter().zip(k.iter()).map(|(z, k)| z * k).sum();
            assert!((fr.at(w) - l).norm() < 1e-12 * l.norm());
        }
    }
}
