//! Assembly of the Radau stage matrix `I - h A (x) J_j` into its compressed-column values by
//! precomputed positions.
//!
//! Every step of the monodromy and tangent routes writes the three stage Jacobians into the `3n x
//! 3n` stage matrix: nine scaled copies of a Jacobian's triplets and the identity. Found by a
//! binary search in each column ([`crate::sim::adapter`]'s `scatter`) that cost half as much as the
//! refactorization itself at nsection n = 1000. A model's Jacobian triplets come in the same order
//! at every call, so the position of every triplet in each of the nine blocks is found once and
//! reused while the triplets' `(row, column)` sequence stays the one the positions were found for
//! (checked at every assembly; a different sequence finds its positions anew).

use super::adapter::scatter;

/// No position: the entry lies outside the stage matrix's pattern.
const OUTSIDE: usize = usize::MAX;

/// The positions of the Jacobian triplets in the stage matrix (see the module doc).
#[derive(Debug, Default)]
pub(super) struct StageSlots {
    /// The `(row, column)` sequence the positions were found for.
    keys: Vec<(usize, usize)>,
    /// Position of triplet `e` in block `(i, j)`: `slots[(3 i + j) m + e]` (`m` triplets).
    slots: Vec<usize>,
    /// Positions of the identity's diagonal (`3 n`).
    diag: Vec<usize>,
}

fn position(col_ptr: &[usize], row_idx: &[usize], r: usize, c: usize) -> usize {
    let (a, b) = (col_ptr[c], col_ptr[c + 1]);
    row_idx[a..b].binary_search(&r).map_or(OUTSIDE, |k| a + k)
}

fn same_keys(keys: &[(usize, usize)], trip: &[(usize, usize, f64)]) -> bool {
    keys.len() == trip.len() && keys.iter().zip(trip).all(|(k, t)| k.0 == t.0 && k.1 == t.1)
}

impl StageSlots {
    /// Find the positions for the triplet sequence of `trip`.
    fn find(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        n: usize,
        trip: &[(usize, usize, f64)],
    ) {
        self.keys = trip.iter().map(|&(r, c, _)| (r, c)).collect();
        let m = trip.len();
        self.slots = vec![OUTSIDE; 9 * m];
        for i in 0..3 {
            for j in 0..3 {
                let out = &mut self.slots[(3 * i + j) * m..(3 * i + j + 1) * m];
                for (o, &(r, c, _)) in out.iter_mut().zip(trip) {
                    *o = position(col_ptr, row_idx, i * n + r, j * n + c);
                }
            }
        }
        self.diag = (0..3 * n)
            .map(|k| position(col_ptr, row_idx, k, k))
            .collect();
    }

    /// `vals <- I - h A (x) [J_1 J_2 J_3]` on the pattern `(col_ptr, row_idx)`; `trip[j]` are the
    /// triplets of `J_j` (entries at one position accumulate). Panics, like the integrator's
    /// assembly, on a nonzero entry outside the pattern: the structural pattern must cover every
    /// Jacobian entry.
    pub(super) fn assemble(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        vals: &mut [f64],
        n: usize,
        h: f64,
        a: &[[f64; 3]; 3],
        trip: &[Vec<(usize, usize, f64)>; 3],
    ) {
        vals.fill(0.0);
        if !trip.iter().all(|t| same_keys(&self.keys, t)) {
            let first: Vec<(usize, usize)> = trip[0].iter().map(|&(r, c, _)| (r, c)).collect();
            if !trip[1..].iter().all(|t| same_keys(&first, t)) {
                return assemble_searched(col_ptr, row_idx, vals, n, h, a, trip);
            }
            self.find(col_ptr, row_idx, n, &trip[0]);
        }
        let m = self.keys.len();
        for i in 0..3 {
            for j in 0..3 {
                let f = -h * a[i][j];
                let slots = &self.slots[(3 * i + j) * m..(3 * i + j + 1) * m];
                for (&s, &(r, c, v)) in slots.iter().zip(&trip[j]) {
                    if s != OUTSIDE {
                        vals[s] += f * v;
                    } else if v != 0.0 {
                        panic!("Jacobian entry ({r}, {c}) lies outside the structural sparsity pattern");
                    }
                }
            }
        }
        for &s in &self.diag {
            vals[s] += 1.0;
        }
    }
}

/// The same assembly by a binary search for every entry (stages whose triplet sequences differ).
fn assemble_searched(
    col_ptr: &[usize],
    row_idx: &[usize],
    vals: &mut [f64],
    n: usize,
    h: f64,
    a: &[[f64; 3]; 3],
    trip: &[Vec<(usize, usize, f64)>; 3],
) {
    let mut shifted = Vec::with_capacity(trip[0].len());
    for i in 0..3 {
        for j in 0..3 {
            shifted.clear();
            shifted.extend(
                trip[j]
                    .iter()
                    .map(|&(r, c, v)| (i * n + r, j * n + c, -h * a[i][j] * v)),
            );
            scatter(col_ptr, row_idx, vals, &shifted);
        }
        shifted.clear();
        shifted.extend((0..n).map(|k| (i * n + k, i * n + k, 1.0)));
        scatter(col_ptr, row_idx, vals, &shifted);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2-state pattern (full 2 x 2 Jacobian) stacked into the 6 x 6 stage pattern, dense.
    fn pattern() -> (Vec<usize>, Vec<usize>) {
        let col_ptr = (0..=6).map(|c| 6 * c).collect();
        let row_idx = (0..6).flat_map(|_| 0..6).collect();
        (col_ptr, row_idx)
    }

    #[test]
    fn positions_assemble_as_the_search_does() {
        let (cp, ri) = pattern();
        let (_, a) = super::super::monodromy::radau3();
        let t = |s: f64| {
            vec![
                (0, 0, -s),
                (1, 0, 2.0),
                (0, 1, 0.5 * s),
                (1, 1, -3.0),
                (1, 1, 0.25),
            ]
        };
        let trip = [t(1.0), t(1.1), t(1.3)];
        let mut want = vec![0.0; 36];
        assemble_searched(&cp, &ri, &mut want, 2, 0.1, &a, &trip);
        let mut slots = StageSlots::default();
        for _ in 0..2 {
            // the first call finds the positions, the second reuses them
            let mut got = vec![7.0; 36];
            slots.assemble(&cp, &ri, &mut got, 2, 0.1, &a, &trip);
            assert_eq!(got, want);
        }
        // a different triplet order finds its positions anew
        let rev: Vec<_> = trip[0].iter().rev().copied().collect();
        let trip2 = [rev.clone(), rev.clone(), rev];
        let mut want2 = vec![0.0; 36];
        assemble_searched(&cp, &ri, &mut want2, 2, 0.2, &a, &trip2);
        let mut got = vec![0.0; 36];
        slots.assemble(&cp, &ri, &mut got, 2, 0.2, &a, &trip2);
        assert_eq!(got, want2);
        // stages whose sequences differ: the search
        let trip3 = [t(1.0), trip2[0].clone(), t(1.0)];
        let mut want3 = vec![0.0; 36];
        assemble_searched(&cp, &ri, &mut want3, 2, 0.2, &a, &trip3);
        let mut got = vec![0.0; 36];
        slots.assemble(&cp, &ri, &mut got, 2, 0.2, &a, &trip3);
        assert_eq!(got, want3);
    }
}
