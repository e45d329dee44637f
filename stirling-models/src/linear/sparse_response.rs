//! `L(s) = K (sI - A0)^-1 B` of a large model by one sparse solve per frequency on the full
//! state, `A0 = J - B C`, never forming the dense reduced matrix.
//!
//! With mass states `A0` keeps the inventory zero of `J` (`c A0 = -(c B) C = 0`, `B` acts on
//! velocities) but `B` lies in the invariant `ker c`, so `(sI - A0)^-1 B` lies there too and
//! equals the reduced response. The last mass equation is replaced by `c z = 0` (as in the
//! Newton system of [`super::equilibrium`]), which keeps the system regular at `s = 0` and does
//! not change the solution elsewhere. The system is scaled by the state scales `D` and solved by
//! the real `2n` embedding of [`super::sparse::ShiftedSolver`] (symbolic analysis once).

use faer::c64;
use nalgebra::{Complex, DVector};

use super::response::FrequencyResponse;
use super::sparse::{ShiftedSolver, SparseMatrix};
use super::LinearError;

/// A prepared sparse SISO frequency response.
#[derive(Clone, Debug)]
pub struct SparseResponse {
    solver: ShiftedSolver,
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
        let mut a0 = j.scaled(scales).plus_outer(&neg_b, &cs);
        let mut rhs: Vec<c64> = neg_b.iter().map(|&v| c64::new(v, 0.0)).collect();
        let fixed = masses.last().copied();
        if let Some(last) = fixed {
            a0.entries.retain(|e| e.0 != last);
            a0.entries
                .extend(masses.iter().map(|&i| (last, i, scales[i])));
            rhs[last] = c64::new(0.0, 0.0);
        }
        let solver = ShiftedSolver::new(&a0, fixed).map_err(|e| LinearError::ShiftFactor {
            shift_re: 0.0,
            shift_im: 0.0,
            why: e.why,
        })?;
        Ok(Self {
            solver,
            rhs,
            k: cs.iter().map(|v| -v).collect(),
        })
    }

    /// `L(s)` (NaN when the shifted system cannot be solved).
    pub fn eval(&self, s: Complex<f64>) -> Complex<f64> {
        let nan = Complex::new(f64::NAN, f64::NAN);
        match self.solver.solve_at(c64::new(s.re, s.im), &self.rhs) {
            Ok(Some(z)) => {
                let l: c64 = z.iter().zip(&self.k).map(|(z, k)| z * k).sum();
                Complex::new(l.re, l.im)
            }
            _ => nan,
        }
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
