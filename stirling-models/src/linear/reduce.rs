//! Inventory reduction (docs/physics.md section 6).
//!
//! With the `full` closure the total gas mass is conserved: `c J = 0` for `c` = ones on the
//! mass states, so `J` has an exact zero eigenvalue, the inventory mode. The dynamic poles are
//! those of `T' J T` on an orthonormal basis `T` of `ker c`: `c J = 0` means `J` maps every
//! state into `ker c`, so `ker c` is invariant and `eig J = eig(T' J T) + {0}`. `T` is the Householder reflector `H = I - 2 u u'`
//! mapping `c/|c|` to `e_j` (`j` the last mass state) without its column `j`, so the reduction
//! costs `O(n^2)`: `H J H = J - 2 u (u'J) - 2 (J u) u' + 4 (u'J u) u u'`, then drop row and column `j`.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The conserved-inventory mode.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InventoryMode {
    /// `c J c' / c c'`: the eigenvalue along the inventory direction (zero to round-off).
    pub eigenvalue: f64,
    /// `max |c J| / max |J|`: how exactly mass is conserved by the Jacobian.
    pub conservation_defect: f64,
    /// The right null vector `r` with `J r = 0`, `c r = 1`: the change of the rest state per
    /// kilogram of charge (state order of the full model).
    pub direction: Vec<f64>,
    /// The mass states that sum to the inventory.
    pub mass_states: Vec<usize>,
}

/// An orthonormal basis of `ker c` as a Householder reflector without column `drop`.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelBasis {
    u: DVector<f64>,
    drop: usize,
}

impl KernelBasis {
    /// The basis for `c` = ones on `mass` (non-empty).
    pub fn new(n: usize, mass: &[usize]) -> Self {
        let drop = *mass.last().expect("at least one mass state");
        let w = 1.0 / (mass.len() as f64).sqrt();
        let mut u = DVector::zeros(n);
        for &i in mass {
            u[i] = w;
        }
        u[drop] -= 1.0;
        let norm = u.norm();
        if norm > 0.0 {
            u /= norm;
        }
        Self { u, drop }
    }

    /// `H v` (full length).
    fn reflect(&self, v: &DVector<f64>) -> DVector<f64> {
        v - &self.u * (2.0 * self.u.dot(v))
    }

    fn remove(&self, v: DVector<f64>) -> DVector<f64> {
        v.remove_row(self.drop)
    }

    /// `T' v` for a column `v` (e.g. an input vector `B`).
    pub fn project(&self, v: &DVector<f64>) -> DVector<f64> {
        self.remove(self.reflect(v))
    }

    /// `T z`: back to full coordinates.
    pub fn expand(&self, z: &DVector<f64>) -> DVector<f64> {
        self.reflect(&z.clone().insert_row(self.drop, 0.0))
    }

    /// `T' A T`.
    pub fn reduce(&self, a: &DMatrix<f64>) -> DMatrix<f64> {
        let u = &self.u;
        let ua = a.tr_mul(u); // (u' A)' as a column
        let au = a * u;
        let uau = u.dot(&au);
        let mut h = a.clone();
        h.ger(-2.0, u, &ua, 1.0);
        h.ger(-2.0, &au, u, 1.0);
        h.ger(4.0 * uau, u, u, 1.0);
        h.remove_row(self.drop).remove_column(self.drop)
    }
}

/// The dynamic part of a Jacobian and, with mass states, the inventory mode.
#[derive(Clone, Debug)]
pub struct Reduction {
    /// `T' J T`, or `J` itself without mass states.
    pub a: DMatrix<f64>,
    /// `T` (absent without mass states).
    pub basis: Option<KernelBasis>,
    pub inventory: Option<InventoryMode>,
}

impl Reduction {
    /// `T' v`, or `v` without mass states.
    pub fn project(&self, v: &DVector<f64>) -> DVector<f64> {
        self.basis
            .as_ref()
            .map_or_else(|| v.clone(), |t| t.project(v))
    }

    /// `T z`, or `z` without mass states.
    pub fn expand(&self, z: &DVector<f64>) -> DVector<f64> {
        self.basis
            .as_ref()
            .map_or_else(|| z.clone(), |t| t.expand(z))
    }

    /// `T' A T` for another matrix on the same states (e.g. the open-loop `A`).
    pub fn reduce(&self, a: &DMatrix<f64>) -> DMatrix<f64> {
        self.basis
            .as_ref()
            .map_or_else(|| a.clone(), |t| t.reduce(a))
    }
}

/// Reduce `j` on `ker c`, `c` = ones on `mass` (no reduction when `mass` is empty).
pub fn reduce(j: &DMatrix<f64>, mass: &[usize]) -> Reduction {
    if mass.is_empty() {
        return Reduction {
            a: j.clone(),
            basis: None,
            inventory: None,
        };
    }
    let n = j.nrows();
    let basis = KernelBasis::new(n, mass);
    let a = basis.reduce(j);
    let inventory = inventory_mode(j, mass, &basis, &a);
    Reduction {
        a,
        basis: Some(basis),
        inventory: Some(inventory),
    }
}

fn inventory_mode(
    j: &DMatrix<f64>,
    mass: &[usize],
    basis: &KernelBasis,
    a: &DMatrix<f64>,
) -> InventoryMode {
    let n = j.nrows();
    let mut c = DVector::zeros(n);
    for &i in mass {
        c[i] = 1.0;
    }
    let cj = j.tr_mul(&c);
    let jmax = j.amax().max(f64::MIN_POSITIVE);
    let eigenvalue = c.dot(&(j * &c)) / c.dot(&c);
    // In reflected coordinates H J H = [[A, g], [0, 0]] (row/column `drop` last):
    // the null vector is z = [-A^-1 g; 1], r = H z scaled so that c r = 1.
    let hjh_col = basis.reflect(&(j * basis.reflect(&unit(n, basis.drop))));
    let g = hjh_col.remove_row(basis.drop);
    let direction = super::solve::solve(a, &(-g)).map(|zr| {
        let r = basis.expand(&zr) + basis.reflect(&unit(n, basis.drop));
        let cr = c.dot(&r);
        (r / cr).iter().copied().collect()
    });
    InventoryMode {
        eigenvalue,
        conservation_defect: cj.amax() / jmax,
        direction: direction.unwrap_or_default(),
        mass_states: mass.to_vec(),
    }
}

fn unit(n: usize, i: usize) -> DVector<f64> {
    let mut e = DVector::zeros(n);
    e[i] = 1.0;
    e
}

/// [`Reduction`] of a large Jacobian given as triplets: the basis `T` and the inventory mode,
/// without `T' J T` (`a` is empty). The null vector solves the Newton system of
/// [`super::equilibrium`] (`J r = 0` with the last mass row replaced by `c r = 1`) by sparse LU.
pub fn reduce_sparse(j: &super::sparse::SparseMatrix, mass: &[usize]) -> Reduction {
    let empty = DMatrix::zeros(0, 0);
    let Some(&last) = mass.last() else {
        return Reduction {
            a: empty,
            basis: None,
            inventory: None,
        };
    };
    let n = j.n;
    let mut flag = vec![false; n];
    for &i in mass {
        flag[i] = true;
    }
    let is_mass = |i: usize| flag[i];
    let (mut cj, mut ccj) = (vec![0.0; n], 0.0);
    for &(_, c, v) in j.entries.iter().filter(|e| is_mass(e.0)) {
        cj[c] += v;
        if is_mass(c) {
            ccj += v;
        }
    }
    let jmax = j.max_abs().max(f64::MIN_POSITIVE);
    let mut e = vec![0.0; n];
    e[last] = 1.0;
    let direction = super::sparse::solve_constrained(j, last, mass, &e)
        .ok()
        .flatten();
    Reduction {
        a: empty,
        basis: Some(KernelBasis::new(n, mass)),
        inventory: Some(InventoryMode {
            eigenvalue: ccj / mass.len() as f64,
            conservation_defect: cj.iter().fold(0.0f64, |a, v| a.max(v.abs())) / jmax,
            direction: direction.unwrap_or_default(),
            mass_states: mass.to_vec(),
        }),
    }
}
