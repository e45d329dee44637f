//! Block Arnoldi on an operator applied to a block of vectors at a time: the Krylov space of a
//! start block, the operator's compression onto it, its leading Ritz values, and the low-rank
//! operator `Z_+ H Z^T` it defines.
//!
//! **Why blocks.** A monodromy product costs one factorization of every step's stage matrix
//! ([`crate::sim::tangent::TangentFlow::apply_block`]) plus a cheap solve per column; keeping the
//! factors of every step between single-vector products is what took nsection n = 1000 to 5 GB.
//! Applied to `k` columns per sweep, the factorizations are shared and nothing is stored, so a
//! few sweeps give a Krylov space of a few dozen dimensions at the memory of the recorded states.
//!
//! **Algorithm.** `V_0` = the orthonormalized start block; sweep `j` applies the operator to `V_j`,
//! orthogonalizes the images against every basis vector (classical Gram-Schmidt, twice; the
//! coefficients go into `H`), and the rest, orthonormalized column by column (modified
//! Gram-Schmidt, twice), is `V_{j+1}`. A column whose rest is below
//! [`DEFLATION`](crate::sim::block_arnoldi::DEFLATION) of its image is dropped (the space is then
//! invariant in that direction), so blocks can shrink. After `m` sweeps `A Z = Z_+ H` holds with
//! `Z = [V_0 .. V_{m-1}]`, `Z_+ = [Z, V_m]`; the Ritz values are the eigenvalues of `H`'s square
//! top (`Z^T A Z`).

use nalgebra::{Complex, DMatrix, DVector};

use super::floquet_arnoldi::ritz_values;
use super::SimError;

/// A column whose rest after orthogonalization is below this fraction of its image is dropped.
pub const DEFLATION: f64 = 1e-12;

/// The block operator: `x <- A x` for the `k` columns of `x` (column-major `n x k`).
pub type BlockOp<'a> = dyn FnMut(&mut [f64], usize) -> Result<(), SimError> + 'a;

/// A block Krylov space and the operator's compression onto it (see the module doc).
#[derive(Clone, Debug)]
pub struct BlockArnoldi {
    n: usize,
    /// The orthonormal basis, one vector per entry: `Z_+`.
    basis: Vec<Vec<f64>>,
    /// The basis vectors already applied (`Z`): the first `applied` of `basis`.
    applied: usize,
    /// `H` by columns: column `j` (the image of basis vector `j`) on the basis vectors.
    h: Vec<Vec<f64>>,
    /// Operator applications (columns).
    pub products: usize,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn axpy(y: &mut [f64], a: f64, x: &[f64]) {
    y.iter_mut().zip(x).for_each(|(yi, xi)| *yi += a * xi);
}

impl BlockArnoldi {
    /// The space of the `k` columns of `start` (column-major `n x k`); columns dependent on the
    /// earlier ones are dropped. An error when nothing is left.
    pub fn new(n: usize, start: &[f64], k: usize) -> Result<Self, SimError> {
        if start.len() != n * k {
            return Err(SimError::DimensionMismatch {
                expected: n * k,
                found: start.len(),
            });
        }
        let mut ba = BlockArnoldi {
            n,
            basis: Vec::new(),
            applied: 0,
            h: Vec::new(),
            products: 0,
        };
        for col in start.chunks_exact(n.max(1)).take(k) {
            let norm = dot(col, col).sqrt();
            if norm > 0.0 && norm.is_finite() {
                ba.append(col.to_vec(), norm, &mut [])?;
            }
        }
        if ba.basis.is_empty() {
            return Err(SimError::BadOption(
                "block Arnoldi: the start block is zero".into(),
            ));
        }
        Ok(ba)
    }

    /// The dimension of the vectors.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Basis vectors applied so far (the size of `H`'s square top).
    pub fn applied(&self) -> usize {
        self.applied
    }

    /// All basis vectors (`Z_+`).
    pub fn len(&self) -> usize {
        self.basis.len()
    }

    /// Whether there is no basis vector (never, after [`BlockArnoldi::new`]).
    pub fn is_empty(&self) -> bool {
        self.basis.is_empty()
    }

    /// Orthogonalize `w` against the basis (twice), record the coefficients in `coef`
    /// (accumulated, as long as the basis), and append the rest when it is above
    /// [`DEFLATION`] of `scale`; whether it was appended.
    fn append(&mut self, mut w: Vec<f64>, scale: f64, coef: &mut [f64]) -> Result<bool, SimError> {
        for _ in 0..2 {
            let c: Vec<f64> = self.basis.iter().map(|b| dot(&w, b)).collect();
            for (b, &ci) in self.basis.iter().zip(&c) {
                axpy(&mut w, -ci, b);
            }
            coef.iter_mut().zip(&c).for_each(|(a, ci)| *a += ci);
        }
        let rest = dot(&w, &w).sqrt();
        if !rest.is_finite() {
            return Err(SimError::SolverFailure {
                t: 0.0,
                why: "block Arnoldi: a product is not finite".into(),
            });
        }
        if rest <= DEFLATION * scale {
            return Ok(false);
        }
        w.iter_mut().for_each(|x| *x /= rest);
        self.basis.push(w);
        if let Some(last) = coef.get_mut(self.basis.len() - 1) {
            *last = rest;
        }
        Ok(true)
    }

    /// Apply `op` to the basis vectors not yet applied (one block) and extend the space;
    /// false when the space is invariant (no new vector, or nothing left to apply).
    pub fn sweep(&mut self, op: &mut BlockOp) -> Result<bool, SimError> {
        let (n, first) = (self.n, self.applied);
        let k = self.basis.len() - first;
        if k == 0 {
            return Ok(false);
        }
        let mut block: Vec<f64> = self.basis[first..].concat();
        op(&mut block, k)?;
        self.products += k;
        self.applied = self.basis.len();
        let before = self.basis.len();
        for col in block.chunks_exact(n) {
            let scale = dot(col, col).sqrt();
            // room for this column's coefficients on every vector it may append
            let mut coef = vec![0.0; self.basis.len() + 1];
            self.append(col.to_vec(), scale, &mut coef)?;
            coef.truncate(self.basis.len());
            self.h.push(coef);
        }
        Ok(self.basis.len() > before)
    }

    /// `H`'s square top `Z^T A Z` (`applied x applied`).
    fn h_top(&self) -> DMatrix<f64> {
        let m = self.applied;
        DMatrix::from_fn(m, m, |r, c| self.h[c].get(r).copied().unwrap_or(0.0))
    }

    /// The Ritz values (eigenvalues of `Z^T A Z`), largest modulus first.
    pub fn ritz(&self) -> Vec<(f64, f64)> {
        ritz_values(&self.h_top())
    }

    /// The Ritz values with their residuals `|A Z y - theta Z y|` (`y` the unit Ritz vector of
    /// `Z^T A Z`), largest modulus first: from `H` alone (`A Z = Z_+ H`), no product.
    pub fn ritz_residuals(&self) -> Vec<((f64, f64), f64)> {
        let (rows, m) = (self.basis.len(), self.applied);
        let top = self.h_top();
        let h = DMatrix::from_fn(rows, m, |r, c| {
            Complex::new(self.h[c].get(r).copied().unwrap_or(0.0), 0.0)
        });
        let scale = top.amax().max(f64::MIN_POSITIVE);
        self.ritz()
            .into_iter()
            .map(|(re, im)| {
                let theta = Complex::new(re, im);
                // inverse iteration, shifted off the eigenvalue by round-off
                let shift = theta + Complex::new(1e-13 * scale, 1e-13 * scale);
                let a = DMatrix::from_fn(m, m, |r, c| {
                    Complex::new(top[(r, c)], 0.0) - if r == c { shift } else { 0.0.into() }
                });
                let lu = a.lu();
                let mut y = DVector::from_fn(m, |i, _| Complex::new(1.0 + 0.1 * i as f64, 0.0));
                for _ in 0..2 {
                    y = lu.solve(&y).unwrap_or_else(|| y.clone());
                    let ny = y.norm();
                    if ny > 0.0 && ny.is_finite() {
                        y /= Complex::new(ny, 0.0);
                    }
                }
                let mut r = &h * &y;
                for i in 0..m {
                    r[i] -= theta * y[i];
                }
                ((re, im), r.norm())
            })
            .collect()
    }

    /// Remove from `v` its components on the applied basis vectors `Z` (twice).
    pub fn orthogonalize(&self, v: &mut [f64]) {
        for _ in 0..2 {
            for b in &self.basis[..self.applied] {
                let c = dot(v, b);
                axpy(v, -c, b);
            }
        }
    }

    /// `v <- Z_+ H Z^T v`: the operator as far as the space knows it (zero on the rest).
    pub fn apply_low_rank(&self, v: &mut [f64]) {
        let c: Vec<f64> = self.basis[..self.applied]
            .iter()
            .map(|b| dot(v, b))
            .collect();
        v.iter_mut().for_each(|x| *x = 0.0);
        for (hj, &cj) in self.h.iter().zip(&c) {
            for (b, &hij) in self.basis.iter().zip(hj) {
                axpy(v, hij * cj, b);
            }
        }
    }

    /// The `k` leading left singular vectors of the images `A Z = Z_+ H` (column-major `n x k`,
    /// fewer when the images have lower rank): the part of the space the operator amplifies
    /// most, a start block for the same operator's neighbours.
    pub fn dominant_images(&self, k: usize) -> Vec<f64> {
        let (rows, m) = (self.basis.len(), self.applied);
        if m == 0 {
            return Vec::new();
        }
        let h = DMatrix::from_fn(rows, m, |r, c| self.h[c].get(r).copied().unwrap_or(0.0));
        let svd = h.svd(true, false);
        let Some(u) = svd.u else {
            return Vec::new();
        };
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
        let mut out = Vec::new();
        for &j in order.iter().take(k) {
            let mut v = vec![0.0; self.n];
            for (b, &uij) in self.basis.iter().zip(u.column(j).iter()) {
                axpy(&mut v, uij, b);
            }
            out.extend(v);
        }
        out
    }
}

/// `k` fixed pseudo-random columns of length `n` (xorshift from `seed`, entries in
/// `[-0.5, 0.5)`), column-major: reproducible start blocks.
pub fn pseudo_random_block(n: usize, k: usize, seed: u64) -> Vec<f64> {
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15 ^ seed.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    (0..n * k)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-normal test operator with a Jordan block at 1, a slow real mode, a complex pair
    /// and a fast cloud: `S diag-ish(...) S^-1` with `S` upper triangular (well conditioned).
    fn operator(n: usize) -> (DMatrix<f64>, Vec<(f64, f64)>) {
        let mut t = DMatrix::<f64>::zeros(n, n);
        t[(0, 0)] = 1.0;
        t[(0, 1)] = 0.3; // Jordan coupling
        t[(1, 1)] = 1.0;
        t[(2, 2)] = 0.71;
        t[(3, 3)] = 0.03;
        t[(3, 4)] = 0.1;
        t[(4, 3)] = -0.1;
        t[(4, 4)] = 0.03;
        t[(5, 5)] = 0.029;
        t[(6, 6)] = 5e-4;
        for i in 7..n {
            t[(i, i)] = 1e-12 * (i as f64).sin();
        }
        let s = DMatrix::from_fn(n, n, |r, c| {
            if r == c {
                1.0
            } else if r < c {
                0.2 * ((r * 7 + c * 3) as f64).cos()
            } else {
                0.0
            }
        });
        let s_inv = s.clone().try_inverse().expect("triangular");
        let want = vec![
            (1.0, 0.0),
            (1.0, 0.0),
            (0.71, 0.0),
            (0.03, 0.1),
            (0.03, -0.1),
            (0.029, 0.0),
            (5e-4, 0.0),
        ];
        (s * t * s_inv, want)
    }

    fn start(n: usize, k: usize) -> Vec<f64> {
        pseudo_random_block(n, k, 1)
    }

    #[test]
    fn leading_ritz_values_and_the_low_rank_operator() {
        let n = 60;
        let (a, want) = operator(n);
        let mut op = |x: &mut [f64], k: usize| -> Result<(), SimError> {
            let xm = DMatrix::from_column_slice(n, k, x);
            x.copy_from_slice((&a * xm).as_slice());
            Ok(())
        };
        let mut ba = BlockArnoldi::new(n, &start(n, 9), 9).unwrap();
        for _ in 0..3 {
            assert!(ba.sweep(&mut op).unwrap());
        }
        assert_eq!((ba.applied(), ba.products), (27, 27));
        let ritz = ba.ritz();
        for (w, got) in want.iter().zip(&ritz) {
            let err = (w.0 - got.0).hypot(w.1.abs() - got.1.abs());
            // the Jordan pair splits by ~sqrt(round-off)
            let tol = if w.0 == 1.0 { 1e-6 } else { 1e-10 };
            assert!(err < tol, "{w:?} vs {got:?}");
        }
        assert!(ritz[7].0.hypot(ritz[7].1) < 1e-10);
        // the low-rank operator acts as `A` on the space's dominant part: on `A v`
        let mut v: Vec<f64> = start(n, 1);
        op(&mut v, 1).unwrap();
        let mut want_av = v.clone();
        op(&mut want_av, 1).unwrap();
        ba.apply_low_rank(&mut v);
        let err = v
            .iter()
            .zip(&want_av)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 1e-10, "low-rank operator: {err:e}");
        // the dominant images span A's range: a new space from them finds the pair at once
        let dom = ba.dominant_images(8);
        assert_eq!(dom.len(), 8 * n);
        let mut b2 = BlockArnoldi::new(n, &dom, 8).unwrap();
        b2.sweep(&mut op).unwrap();
        b2.sweep(&mut op).unwrap();
        let r2 = b2.ritz();
        assert!((r2[2].0 - 0.71).abs() < 1e-10, "{r2:?}");
    }

    #[test]
    fn an_invariant_start_deflates_and_a_bad_start_is_an_error() {
        let n = 5;
        let a = DMatrix::<f64>::from_diagonal(&nalgebra::DVector::from_vec(vec![
            2.0, 0.5, 0.1, 0.0, 0.0,
        ]));
        let mut op = |x: &mut [f64], k: usize| -> Result<(), SimError> {
            let xm = DMatrix::from_column_slice(n, k, x);
            x.copy_from_slice((&a * xm).as_slice());
            Ok(())
        };
        // e1 and e2, plus a dependent column (dropped)
        let start = [
            1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0,
        ];
        let mut ba = BlockArnoldi::new(n, &start, 3).unwrap();
        assert_eq!(ba.len(), 2);
        assert!(!ba.sweep(&mut op).unwrap(), "invariant: no new vector");
        assert_eq!(ba.ritz(), vec![(2.0, 0.0), (0.5, 0.0)]);
        assert!(!ba.sweep(&mut op).unwrap(), "nothing left to apply");
        assert!(BlockArnoldi::new(n, &[0.0; 5], 1).is_err());
        assert!(matches!(
            BlockArnoldi::new(n, &[1.0; 4], 1),
            Err(SimError::DimensionMismatch { .. })
        ));
    }
}
