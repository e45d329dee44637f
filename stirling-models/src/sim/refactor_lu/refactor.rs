//! The numeric refactorization on a kept pattern (Gilbert-Peierls without the reach's search)
//! and its pivot test.
//!
//! The test accepts a pivot that is at least [`PIVOT_TOLERANCE`] times the largest entry below
//! it in its column (the multipliers stay below the tolerance's inverse: partial pivoting's
//! threshold test) *or* the largest right of it in its row (the pivot row, scaled by the pivot,
//! stays below it: the same test on the transpose). Either bounds what one elimination step adds
//! to an entry by the tolerance's inverse times an entry already there, which is what the
//! threshold test is for; the row test is what lets the diagonal pattern pivot on a mass
//! state's 1 above pressures' entries of 1e7 (its row holds entries of 1e-8).

use faer::sparse::SparseColMatRef;

use super::{LuPattern, LuValues, PIVOT_TOLERANCE};

/// Work arrays of one refactorization.
#[derive(Debug)]
pub(super) struct Scratch {
    /// The column being eliminated (zero between calls).
    x: Vec<f64>,
    /// Pivots that failed the column test, to be tried by the row test.
    suspects: Vec<usize>,
    /// The largest off-diagonal entry of each row of `U`.
    row_max: Vec<f64>,
}

impl Scratch {
    pub(super) fn new(n: usize) -> Self {
        Self {
            x: vec![0.0; n],
            suspects: Vec::with_capacity(n),
            row_max: vec![0.0; n],
        }
    }
}

/// Gilbert-Peierls with the kept pivots and patterns. False (the values then unusable)
/// when a pivot fails the test (module doc) or is not finite.
pub(super) fn refactor(
    p: &LuPattern,
    v: &mut LuValues,
    w: &mut Scratch,
    a: SparseColMatRef<'_, usize, f64>,
) -> bool {
    w.suspects.clear();
    let x = &mut w.x;
    let (ap, ai, av) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
    for (j, &c) in p.col_perm.iter().enumerate() {
        for e in ap[c]..ap[c + 1] {
            x[p.row_inv[ai[e]]] += av[e];
        }
        let last = p.u_ptr[j + 1] - 1;
        let (ui, uv) = (&p.u_idx[p.u_ptr[j]..last], &mut v.u[p.u_ptr[j]..last]);
        for (&r, u) in ui.iter().zip(uv) {
            let xr = x[r];
            x[r] = 0.0;
            *u = xr;
            let (a, b) = (p.l_ptr[r] + 1, p.l_ptr[r + 1]);
            for (&i, &l) in p.l_idx[a..b].iter().zip(&v.l[a..b]) {
                x[i] -= l * xr;
            }
        }
        let pivot = x[j];
        x[j] = 0.0;
        let below = p.l_ptr[j] + 1..p.l_ptr[j + 1];
        let largest = p.l_idx[below.clone()]
            .iter()
            .fold(0.0f64, |m, &i| m.max(x[i].abs()));
        let regular = pivot.is_finite() && pivot != 0.0;
        if regular && pivot.abs() <= PIVOT_TOLERANCE * largest {
            w.suspects.push(j);
        }
        v.u[last] = pivot;
        v.u_inv_diag[j] = 1.0 / pivot;
        for k in below {
            let i = p.l_idx[k];
            v.l[k] = x[i] / pivot;
            x[i] = 0.0;
        }
        if !regular {
            x.fill(0.0);
            return false;
        }
    }
    w.suspects.is_empty() || rows_dominated(p, v, &w.suspects, &mut w.row_max)
}

/// Whether every pivot in `suspects` passes the row test.
fn rows_dominated(p: &LuPattern, v: &LuValues, suspects: &[usize], row_max: &mut [f64]) -> bool {
    row_max.fill(0.0);
    for j in 0..p.u_ptr.len() - 1 {
        let off = p.u_ptr[j]..p.u_ptr[j + 1] - 1;
        for (&r, &u) in p.u_idx[off.clone()].iter().zip(&v.u[off]) {
            row_max[r] = row_max[r].max(u.abs());
        }
    }
    suspects.iter().all(|&j| {
        let pivot = v.u[p.u_ptr[j + 1] - 1];
        pivot.abs() > PIVOT_TOLERANCE * row_max[j]
    })
}
