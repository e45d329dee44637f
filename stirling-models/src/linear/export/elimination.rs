//! The inventory elimination of the export: the last mass state is dropped, its deviation being
//! minus the sum of the other mass deviations (constant charge). `x - x* = T z` with `T` the
//! identity on the kept states and a row of `-1` on the mass columns for the eliminated one, and
//! `P` picks the kept rows, so `A_z = P A T`, `B_z = P B`, `C_z = C T`. All of it works on
//! nonzeros: nothing here is dense in the state count.

use std::collections::BTreeMap;

use nalgebra::DVector;
use stirling_dsl::Model;

use super::Triplets;
use crate::linear::equilibrium::mass_states;

/// Elimination of the last mass state: kept states, and the eliminated one with the others.
pub(super) struct Elimination {
    pub keep: Vec<usize>,
    /// Eliminated state and the mass states (it included).
    pub last: Option<(usize, Vec<usize>)>,
    /// Per kept coordinate: whether it is a mass state.
    mass: Vec<bool>,
}

impl Elimination {
    pub fn new(model: &dyn Model) -> Self {
        Self::of(model.n_states(), &mass_states(model))
    }

    /// For `n` states with these mass states (the last one eliminated).
    pub fn of(n: usize, mass: &[usize]) -> Self {
        let mut is = vec![false; n];
        mass.iter().for_each(|&i| is[i] = true);
        let (keep, last): (Vec<usize>, _) = match mass.last() {
            Some(&l) => (
                (0..n).filter(|&i| i != l).collect(),
                Some((l, mass.to_vec())),
            ),
            None => ((0..n).collect(), None),
        };
        let mass = if last.is_some() {
            keep.iter().map(|&i| is[i]).collect()
        } else {
            vec![false; keep.len()]
        };
        Self { keep, last, mass }
    }

    fn last_state(&self) -> Option<usize> {
        self.last.as_ref().map(|(l, _)| *l)
    }

    /// The kept coordinate of each full state (`None` for the eliminated one).
    fn positions(&self, n: usize) -> Vec<Option<usize>> {
        let mut pos = vec![None; n];
        for (k, &i) in self.keep.iter().enumerate() {
            pos[i] = Some(k);
        }
        pos
    }

    /// `P A T` from the nonzeros of `A` (`n x n`), as row-major triplets: no dense matrix, so
    /// the export of n = 10,000 sections (20,008 states) stays linear in the nonzeros.
    pub fn a(&self, n: usize, a: &[(usize, usize, f64)]) -> Triplets {
        let m = self.keep.len();
        let pos = self.positions(n);
        let mass_cols: Vec<usize> = (0..m).filter(|&j| self.mass[j]).collect();
        let last = self.last_state();
        let mut acc: BTreeMap<(usize, usize), f64> = BTreeMap::new();
        for &(r, c, v) in a {
            let Some(i) = pos[r] else { continue };
            if let Some(j) = pos[c] {
                *acc.entry((i, j)).or_default() += v;
            }
            if Some(c) == last {
                for &j in &mass_cols {
                    *acc.entry((i, j)).or_default() -= v;
                }
            }
        }
        let mut t = Triplets::new(m, m);
        acc.into_iter().for_each(|((i, j), v)| t.push(i, j, v));
        t
    }

    /// `P b`.
    pub fn b(&self, b: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(self.keep.len(), self.keep.iter().map(|&i| b[i]))
    }

    /// `(c' T)'`.
    pub fn c(&self, c: &DVector<f64>) -> DVector<f64> {
        DVector::from_fn(self.keep.len(), |j, _| match self.last_state() {
            Some(l) if self.mass[j] => c[self.keep[j]] - c[l],
            _ => c[self.keep[j]],
        })
    }

    /// `T` (full x kept) as row-major triplets.
    pub fn basis(&self, n: usize) -> Triplets {
        let pos = self.positions(n);
        let mut t = Triplets::new(n, self.keep.len());
        for (i, p) in pos.iter().enumerate() {
            match p {
                Some(k) => t.push(i, *k, 1.0),
                None => (0..self.keep.len())
                    .filter(|&j| self.mass[j])
                    .for_each(|j| t.push(i, j, -1.0)),
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::*;

    /// 4 states, mass states 1 and 3 (3 eliminated), a dense `A` with no zero.
    fn case() -> (Elimination, DMatrix<f64>) {
        let a = DMatrix::from_fn(4, 4, |i, j| 1.0 + (i * 4 + j) as f64 * 0.5);
        (Elimination::of(4, &[1, 3]), a)
    }

    #[test]
    fn sparse_pat_equals_the_dense_product() {
        let (el, a) = case();
        let t = el.basis(4).dense();
        let p = DMatrix::from_fn(3, 4, |k, i| f64::from(u8::from(el.keep[k] == i)));
        let want = &p * &a * &t;
        let nz = Triplets::of_dense(&a).entries().collect::<Vec<_>>();
        assert_eq!(el.a(4, &nz).dense(), want);
        let b = DVector::from_vec(vec![1.0, 2.0, 3.0, 4.0]);
        assert_eq!(el.b(&b), &p * &b);
        assert_eq!(el.c(&b), t.transpose() * &b);
    }

    #[test]
    fn the_basis_keeps_the_charge() {
        let (el, _) = case();
        let t = el.basis(4).dense();
        // the mass states' rows of T sum to zero: x - x* = T z never changes the charge
        let charge = t.row(1) + t.row(3);
        assert!(charge.iter().all(|v| *v == 0.0), "{charge}");
        assert_eq!(
            t.row(3).iter().copied().collect::<Vec<_>>(),
            vec![0.0, -1.0, 0.0]
        );
    }

    #[test]
    fn without_mass_states_nothing_is_eliminated() {
        let el = Elimination::of(3, &[]);
        assert!(el.last.is_none());
        assert_eq!(el.basis(3).dense(), DMatrix::identity(3, 3));
    }
}
