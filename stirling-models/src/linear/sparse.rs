//! Sparse linear algebra of the large-model route: the Jacobian as triplets, its product with a
//! vector, faer sparse LU solves of `M x = b` (real, also with one row replaced by a
//! conservation constraint) and of `(A - sigma I) z = x` for a complex shift by a complex
//! sparse LU. The symbolic analysis (column ordering, elimination structure) of `A - sigma I`
//! is done once per pattern and reused for every shift, as `sim::monodromy` reuses its stage
//! pattern.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, SparseColMatRef, Triplet};
use faer::{c64, Mat};

/// A square sparse matrix as coordinate triplets (entries at one position are summed).
#[derive(Clone, Debug, PartialEq)]
pub struct SparseMatrix {
    pub n: usize,
    pub entries: Vec<(usize, usize, f64)>,
}

impl SparseMatrix {
    /// `y = A x` (complex `x`).
    pub fn mul(&self, x: &[c64]) -> Vec<c64> {
        let mut y = vec![c64::new(0.0, 0.0); self.n];
        for &(i, j, v) in &self.entries {
            y[i] += x[j] * v;
        }
        y
    }

    /// `D^-1 A D` for `D = diag(d)` (a similarity: the same eigenvalues).
    pub fn scaled(&self, d: &[f64]) -> Self {
        Self {
            n: self.n,
            entries: self
                .entries
                .iter()
                .map(|&(i, j, v)| (i, j, v * d[j] / d[i]))
                .collect(),
        }
    }

    /// `A + b c'` for sparse vectors given densely (only their nonzeros are added).
    pub fn plus_outer(&self, b: &[f64], c: &[f64]) -> Self {
        let mut entries = self.entries.clone();
        for (i, &bi) in b.iter().enumerate().filter(|(_, v)| **v != 0.0) {
            for (j, &cj) in c.iter().enumerate().filter(|(_, v)| **v != 0.0) {
                entries.push((i, j, bi * cj));
            }
        }
        Self { n: self.n, entries }
    }

    /// `max |a_ij|` over the summed entries (an upper bound would do: used for tolerances).
    pub fn max_abs(&self) -> f64 {
        self.entries.iter().fold(0.0f64, |m, e| m.max(e.2.abs()))
    }
}

/// Why a sparse factorization failed (symbolic or numeric; a singular matrix included).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("sparse LU: {why}")]
pub struct SparseLuError {
    pub why: String,
}

fn fail(e: impl std::fmt::Debug) -> SparseLuError {
    SparseLuError {
        why: format!("{e:?}"),
    }
}

fn assemble(
    n: usize,
    entries: &[Triplet<usize, usize, f64>],
) -> Result<SparseColMat<usize, f64>, SparseLuError> {
    SparseColMat::try_new_from_triplets(n, n, entries).map_err(fail)
}

/// Solve the real system `M x = b`; `None` when the result is not finite.
pub fn solve_real(m: &SparseMatrix, b: &[f64]) -> Result<Option<Vec<f64>>, SparseLuError> {
    let t: Vec<_> = m
        .entries
        .iter()
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    let a = assemble(m.n, &t)?;
    let lu = a.sp_lu().map_err(fail)?;
    let rhs = Mat::<f64>::from_fn(m.n, 1, |i, _| b[i]);
    let x = lu.solve(&rhs);
    let x: Vec<f64> = (0..m.n).map(|i| x[(i, 0)]).collect();
    Ok(x.iter().all(|v| v.is_finite()).then_some(x))
}

/// Solve `M x = b` where `M` is `a` with its row `row` replaced by ones in the columns `cols`
/// (a conservation constraint such as `sum of the masses = charge`), without that dense row
/// in the factorization: `M = B + e_row d'` with `B` = `a` with the row replaced by `e_row'`
/// and `d` = the ones minus `e_row`, so by Sherman-Morrison `x = z - y (d'z) / (1 + d'y)` with
/// `B z = b`, `B y = e_row` (one sparse LU, two solves). A dense row makes the column
/// elimination tree of the LU one chain and its fronts dense: at 20,008 states the direct
/// factorization spent most of a second per Newton step in dense `gemm`. Falls back to the
/// direct factorization when `1 + d'y` is tiny against `|d||y|`.
pub fn solve_constrained(
    a: &SparseMatrix,
    row: usize,
    cols: &[usize],
    b: &[f64],
) -> Result<Option<Vec<f64>>, SparseLuError> {
    let weighted: Vec<(usize, f64)> = cols.iter().map(|&i| (i, 1.0)).collect();
    solve_weighted_constrained(a, row, &weighted, b)
}

/// [`solve_constrained`] with the constraint row `sum w_i x_i` (`cols`: `(i, w_i)`).
pub fn solve_weighted_constrained(
    a: &SparseMatrix,
    row: usize,
    cols: &[(usize, f64)],
    b: &[f64],
) -> Result<Option<Vec<f64>>, SparseLuError> {
    let n = a.n;
    let mut t: Vec<_> = a
        .entries
        .iter()
        .filter(|e| e.0 != row)
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    t.push(Triplet::new(row, row, 1.0));
    let lu = assemble(n, &t)?.sp_lu().map_err(fail)?;
    let rhs = Mat::<f64>::from_fn(n, 2, |i, c| match c {
        0 => b[i],
        _ => f64::from(i == row),
    });
    let s = lu.solve(&rhs);
    let d_dot = |c: usize| cols.iter().map(|&(i, w)| w * s[(i, c)]).sum::<f64>() - s[(row, c)];
    let (dz, dy) = (d_dot(0), d_dot(1));
    let y_norm = (0..n).map(|i| s[(i, 1)].abs()).fold(0.0, f64::max);
    if (1.0 + dy).abs() <= 1e-10 * (cols.len() as f64).sqrt() * y_norm.max(1.0) {
        let mut m = a.clone();
        m.entries.retain(|e| e.0 != row);
        m.entries.extend(cols.iter().map(|&(i, w)| (row, i, w)));
        return solve_real(&m, b);
    }
    let x: Vec<f64> = (0..n)
        .map(|i| s[(i, 0)] - s[(i, 1)] * dz / (1.0 + dy))
        .collect();
    Ok(x.iter().all(|v| v.is_finite()).then_some(x))
}

/// `(A - sigma I)^-1` for complex shifts of one matrix, by a complex sparse LU of dimension n
/// (the real `2n` embedding it replaced had twice the dimension and more fill: the dominant
/// poles at n = 10,000 went from 1.15 s to 0.80 s).
#[derive(Clone, Debug)]
pub struct ShiftedSolver {
    /// `A` in compressed columns with every diagonal entry present (the shift's pattern).
    pattern: SparseColMat<usize, c64>,
    /// Where each diagonal entry sits among the pattern's values.
    diag: Vec<usize>,
    symbolic: SymbolicLu<usize>,
    lu: Option<Lu<usize, c64>>,
}

impl ShiftedSolver {
    /// Analyse the pattern of `A - sigma I` (every diagonal entry present).
    pub fn new(a: &SparseMatrix) -> Result<Self, SparseLuError> {
        let pattern = shifted(a, c64::new(0.0, 0.0))?;
        let diag = diagonal_positions(&pattern)?;
        let symbolic = SymbolicLu::try_new(pattern.symbolic()).map_err(fail)?;
        Ok(Self {
            pattern,
            diag,
            symbolic,
            lu: None,
        })
    }

    /// The LU of `A - sigma I`: the pattern's values with `sigma` taken from the diagonal
    /// (no triplets sorted per shift: at n = 10,000 that was an eighth of `linearize`).
    fn lu_at(&self, sigma: c64) -> Result<Lu<usize, c64>, SparseLuError> {
        let mut val = self.pattern.val().to_vec();
        for &k in &self.diag {
            val[k] -= sigma;
        }
        let mat = SparseColMatRef::new(self.pattern.symbolic(), &val);
        Lu::try_new_with_symbolic(self.symbolic.clone(), mat).map_err(fail)
    }

    /// Factor `A - sigma I` (the symbolic analysis is reused).
    pub fn factor(&mut self, sigma: c64) -> Result<(), SparseLuError> {
        self.lu = Some(self.lu_at(sigma)?);
        Ok(())
    }

    /// `z = (A - sigma I)^-1 x` for the last factored `sigma`; `None` if not finite or unfactored.
    pub fn solve(&self, x: &[c64]) -> Option<Vec<c64>> {
        solve_complex(self.lu.as_ref()?, x)
    }

    /// Factor at `sigma` and solve once, leaving the stored factorization alone.
    pub fn solve_at(&self, sigma: c64, x: &[c64]) -> Result<Option<Vec<c64>>, SparseLuError> {
        Ok(solve_complex(&self.lu_at(sigma)?, x))
    }
}

fn solve_complex(lu: &Lu<usize, c64>, x: &[c64]) -> Option<Vec<c64>> {
    let rhs = Mat::<c64>::from_fn(x.len(), 1, |i, _| x[i]);
    let s = lu.solve(&rhs);
    let z: Vec<c64> = (0..x.len()).map(|i| s[(i, 0)]).collect();
    z.iter()
        .all(|v| v.re.is_finite() && v.im.is_finite())
        .then_some(z)
}

/// The position of each diagonal entry among the values of `m` (every one present).
fn diagonal_positions(m: &SparseColMat<usize, c64>) -> Result<Vec<usize>, SparseLuError> {
    let s = m.symbolic();
    (0..s.ncols())
        .map(|j| {
            let r = s.col_range(j);
            s.row_idx()[r.clone()]
                .iter()
                .position(|&i| i == j)
                .map(|k| r.start + k)
                .ok_or_else(|| fail(format!("no diagonal entry in column {j}")))
        })
        .collect()
}

/// `A - sigma I` as a complex sparse matrix (every diagonal entry present).
fn shifted(a: &SparseMatrix, sigma: c64) -> Result<SparseColMat<usize, c64>, SparseLuError> {
    let mut t: Vec<Triplet<usize, usize, c64>> = Vec::with_capacity(a.entries.len() + a.n);
    t.extend(
        a.entries
            .iter()
            .map(|&(i, j, v)| Triplet::new(i, j, c64::new(v, 0.0))),
    );
    t.extend((0..a.n).map(|k| Triplet::new(k, k, -sigma)));
    SparseColMat::try_new_from_triplets(a.n, a.n, &t).map_err(fail)
}
