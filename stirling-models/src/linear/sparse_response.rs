//! `L(s) = K (sI - A0)^-1 B` of a large model by one sparse solve per frequency on the full
//! state, `A0 = J - B C`, never forming the dense reduced matrix.
//!
//! With mass states `A0` keeps the inventory zero of `J` (`c A0 = -(c B) C = 0`, `B` acts on
//! velocities) but `B` lies in the invariant `ker c`, so `(sI - A0)^-1 B` lies there too and equals
//! the reduced response. `sI - A0` is singular only at `s = 0` (the inventory zero), and `L` is
//! evaluated on `s = jw`, `w > 0` (the analysis grid, the margins' searches), so the system is
//! solved as it is. (It used to replace the last mass equation by `c z = 0`, as the equilibrium's
//! Newton system does, to stay regular at `s = 0`; that dense row made the factorization's fronts
//! dense: `linearize --n 1000` spent 47 s in those solves.) At `s = 0` alone the constraint is
//! used, by Sherman-Morrison on the sparse matrix
//! ([`crate::linear::sparse::solve_weighted_constrained`]). The system is scaled by the state
//! scales `D` and solved by the complex sparse LU of [`crate::linear::sparse::ShiftedSolver`]
//! (symbolic analysis once).

use faer::c64;
use nalgebra::{Complex, DVector};

use super::response::FrequencyResponse;
use super::sparse::{solve_real, solve_weighted_constrained, ShiftedSolver, SparseMatrix};
use super::LinearError;

/// A prepared sparse SISO frequency response.
#[derive(Clone, Debug)]
pub struct SparseResponse {
    solver: ShiftedSolver,
    /// `A0` (scaled) and the inventory constraint `(last mass row, (mass, scale))`: the
    /// system at `s = 0`, where `A0 - sI` is singular, by [`solve_weighted_constrained`].
    a0: SparseMatrix,
    constraint: Option<(usize, Vec<(usize, f64)>)>,
    /// `-D^-1 B` with the constraint row zero.
    rhs: Vec<c64>,
    /// `K D`.
    k: Vec<f64>,
}

impl SparseResponse {
    /// Prepare `L(s) = k' (sI - (J - b c'))^-1 b` for `J` as triplets.
    pub fn new(
        j: &SparseMatrix,
        b: &DVector<f64>,
        c: &DVector<f64>,
        scales: &[f64],
        masses: &[usize],
    ) -> Result<Self, LinearError> {
        let bs: Vec<f64> = b.iter().zip(scales).map(|(v, d)| v / d).collect();
        let cs: Vec<f64> = c.iter().zip(scales).map(|(v, d)| v * d).collect();
        let neg_b: Vec<f64> = bs.iter().map(|v| -v).collect();
        let a0 = j.scaled(scales).plus_outer(&neg_b, &cs);
        let rhs: Vec<c64> = neg_b.iter().map(|&v| c64::new(v, 0.0)).collect();
        let solver = ShiftedSolver::new(&a0).map_err(|e| LinearError::ShiftFactor {
            shift_re: 0.0,
            shift_im: 0.0,
            why: e.why,
        })?;
        let constraint = masses
            .last()
            .map(|&last| (last, masses.iter().map(|&i| (i, scales[i])).collect()));
        Ok(Self {
            solver,
            a0,
            constraint,
            rhs,
            k: cs.iter().map(|v| -v).collect(),
        })
    }

    /// `L(s)` (NaN when the shifted system cannot be solved).
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        let nan = Complex::new(f64::NAN, f64::NAN);
        if s == Complex::new(0.0, 0.0) {
            return self.at_zero().unwrap_or(nan);
        }
        match self.solver.solve_at(c64::new(s.re, s.im), &self.rhs) {
            Ok(Some(z)) => {
                let l: c64 = z.iter().zip(&self.k).map(|(z, k)| z * k).sum();
                Complex::new(l.re, l.im)
            }
            _ => nan,
        }
    }
}

impl SparseResponse {
    /// `L(0)`: `A0 z = -b` on `ker c` (the last mass row replaced by `c z = 0`).
    fn at_zero(&self) -> Option<Complex<f64>> {
        let b: Vec<f64> = self.rhs.iter().map(|z| z.re).collect();
        let z = match &self.constraint {
            Some((last, w)) => {
                let mut b = b;
                b[*last] = 0.0;
                solve_weighted_constrained(&self.a0, *last, w, &b)
            }
            None => solve_real(&self.a0, &b),
        }
        .ok()??;
        let l: f64 = z.iter().zip(&self.k).map(|(z, k)| z * k).sum();
        Some(Complex::new(l, 0.0))
    }
}

/// `L(jw)` by the dense reduced route or the sparse full-state route.
#[derive(Clone, Debug)]
pub enum LoopResponse {
    Dense(FrequencyResponse),
    Sparse(Box<SparseResponse>),
}

impl LoopResponse {
    /// `L(s)`.
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        match self {
            Self::Dense(r) => r.eval(s),
            Self::Sparse(r) => r.eval(s),
        }
    }

    /// `L(j w)`.
    pub fn at(&self, w: f64) -> Complex<f64> {
        self.eval(Complex::new(0.0, w))
    }
}
