//! The linear results as control engineers use them: the state-space `A, B, C, D` of the loop
//! broken at its channel and of the closed loop, with state, input and output names, the Bode
//! data and the pole tables (as MATLAB's `damp`), in a form python-control
//! (`control.ss(A, B, C, D)`) and MATLAB (`ss(A, B, C, D)` after `jsondecode`) read directly.
//!
//! `A` has the poles the report gives: with the `full` closure it is reduced by the inventory
//! constraint, so it has no zero eigenvalue from the conserved mass. The reduction eliminates the
//! last mass state (`m_last - m_last* = -` the sum of the other mass deviations at constant
//! charge): the coordinates keep the model's state names and `A` keeps its sparsity, and it is
//! similar to the orthogonal reduction of [`crate::linear::reduce`]. `basis` gives `T` with `x - x*
//! = T z`. From [`SPARSE_FROM`](crate::linear::export::SPARSE_FROM) states on `A` is also written
//! as triplets, above [`DENSE_UP_TO`](crate::linear::export::DENSE_UP_TO) only so.

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use super::equilibrium::mass_states;
use super::{Linearization, Pole};

/// The largest state count written as dense matrices.
pub const DENSE_UP_TO: usize = 500;
/// The smallest state count also written as triplets.
pub const SPARSE_FROM: usize = 200;

/// The sign convention, in words.
pub const CONVENTION: &str = "x' = A x + B u, y = C x + D u; the loop closes with negative unity feedback u = -y, so closed_loop.a = broken_loop.a - B C; margins of broken_loop as MATLAB's margin and python-control's control.margin";

/// A sparse matrix: 0-based row and column indices and the nonzero values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Triplets {
    pub rows: usize,
    pub cols: usize,
    pub i: Vec<usize>,
    pub j: Vec<usize>,
    pub v: Vec<f64>,
}

/// One row of the pole table (MATLAB's `damp`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Damp {
    pub re: f64,
    pub im: f64,
    /// `|s|` (rad/s).
    pub natural_rad_s: f64,
    /// `-re / |s|`.
    pub damping_ratio: f64,
    /// `-1 / re` (s); absent for `re = 0`.
    pub time_constant_s: Option<f64>,
}

/// A single-input single-output state-space system.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateSpace {
    /// `A` by rows (absent above [`DENSE_UP_TO`] states).
    pub a: Option<Vec<Vec<f64>>>,
    /// `A` as triplets (from [`SPARSE_FROM`] states on).
    pub a_sparse: Option<Triplets>,
    /// `B`, one column.
    pub b: Vec<Vec<f64>>,
    /// `C`, one row.
    pub c: Vec<Vec<f64>>,
    /// `D` (1 x 1).
    pub d: Vec<Vec<f64>>,
    pub input: String,
    pub output: String,
    /// Poles with natural frequency and damping ratio, least stable first.
    pub poles: Vec<Damp>,
}

/// Bode data of the broken loop.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BodeData {
    pub w_rad_s: Vec<f64>,
    pub magnitude: Vec<f64>,
    pub magnitude_db: Vec<f64>,
    pub phase_deg: Vec<f64>,
}

/// What `stirling linearize --ss FILE` writes (and `--json` carries as `state_space`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateSpaceExport {
    pub model: String,
    pub n: usize,
    pub closure: String,
    pub convention: String,
    /// Whether `A` is reduced by the inventory constraint (`full` closure with mass states).
    pub inventory_reduced: bool,
    /// How: the state eliminated, or why nothing is.
    pub reduction: String,
    /// The coordinates of `A` (the model's states without the eliminated one).
    pub states: Vec<String>,
    /// The model's states, in the order of `basis` rows and of the equilibrium.
    pub full_states: Vec<String>,
    /// The equilibrium `x*` (full state order).
    pub equilibrium: Vec<f64>,
    /// `T` by rows (full x reduced) with `x - x* = T z`; absent without reduction or above
    /// [`DENSE_UP_TO`] states.
    pub basis: Option<Vec<Vec<f64>>>,
    pub broken_loop: StateSpace,
    pub closed_loop: StateSpace,
    pub bode: BodeData,
}

fn rows(m: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect())
        .collect()
}

fn triplets(m: &DMatrix<f64>) -> Triplets {
    let mut t = Triplets {
        rows: m.nrows(),
        cols: m.ncols(),
        i: Vec::new(),
        j: Vec::new(),
        v: Vec::new(),
    };
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            let v = m[(i, j)];
            if v != 0.0 {
                t.i.push(i);
                t.j.push(j);
                t.v.push(v);
            }
        }
    }
    t
}

fn damp(p: &[Pole]) -> Vec<Damp> {
    p.iter()
        .map(|p| Damp {
            re: p.re,
            im: p.im,
            natural_rad_s: p.natural_rad_s,
            damping_ratio: p.damping_ratio,
            time_constant_s: (p.re != 0.0).then(|| -1.0 / p.re),
        })
        .collect()
}

/// A matrix's nonzeros, row-major (the dense route's matrices).
fn entries(m: &DMatrix<f64>) -> Vec<(usize, usize, f64)> {
    let t = triplets(m);
    (0..t.v.len()).map(|k| (t.i[k], t.j[k], t.v[k])).collect()
}

/// The dense form of triplets (small systems only).
fn dense(t: &Triplets) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(t.rows, t.cols);
    for k in 0..t.v.len() {
        m[(t.i[k], t.j[k])] += t.v[k];
    }
    m
}

fn system(a: Triplets, b: &DVector<f64>, c: &DVector<f64>, poles: &[Pole]) -> StateSpace {
    let n = a.rows;
    StateSpace {
        a: (n <= DENSE_UP_TO).then(|| rows(&dense(&a))),
        a_sparse: (n >= SPARSE_FROM).then_some(a),
        b: b.iter().map(|v| vec![*v]).collect(),
        c: vec![c.iter().copied().collect()],
        d: vec![vec![0.0]],
        input: String::new(),
        output: String::new(),
        poles: damp(poles),
    }
}

/// Elimination of the last mass state: kept states, and the eliminated one with the others.
struct Elimination {
    keep: Vec<usize>,
    /// Eliminated state and the mass states (it included).
    last: Option<(usize, Vec<usize>)>,
    /// Per kept coordinate: whether it is a mass state.
    mass: Vec<bool>,
}

impl Elimination {
    fn new(model: &dyn Model) -> Self {
        let n = model.n_states();
        let mass = mass_states(model);
        let mut is = vec![false; n];
        mass.iter().for_each(|&i| is[i] = true);
        let (keep, last): (Vec<usize>, _) = match mass.last() {
            Some(&l) => ((0..n).filter(|&i| i != l).collect(), Some((l, mass))),
            None => ((0..n).collect(), None),
        };
        let mass = if last.is_some() {
            keep.iter().map(|&i| is[i]).collect()
        } else {
            vec![false; keep.len()]
        };
        Self { keep, last, mass }
    }

    /// `-1` where the kept coordinate `j` is a mass state (the eliminated state's row of `T`).
    fn is_mass(&self, j: usize) -> bool {
        self.mass[j]
    }

    /// `P A T` from the nonzeros of `A` (`n x n`), as row-major triplets: no dense matrix, so
    /// the export of n = 10,000 sections (20,004 states) stays linear in the nonzeros.
    fn a(&self, n: usize, a: &[(usize, usize, f64)]) -> Triplets {
        let m = self.keep.len();
        let mut pos = vec![None; n];
        for (k, &i) in self.keep.iter().enumerate() {
            pos[i] = Some(k);
        }
        let mass_cols: Vec<usize> = (0..m).filter(|&j| self.is_mass(j)).collect();
        let last = self.last.as_ref().map(|(l, _)| *l);
        let mut acc: std::collections::BTreeMap<(usize, usize), f64> = Default::default();
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
        let mut t = Triplets {
            rows: m,
            cols: m,
            i: Vec::new(),
            j: Vec::new(),
            v: Vec::new(),
        };
        for ((i, j), v) in acc.into_iter().filter(|(_, v)| *v != 0.0) {
            t.i.push(i);
            t.j.push(j);
            t.v.push(v);
        }
        t
    }

    /// `P b`.
    fn b(&self, b: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(self.keep.len(), self.keep.iter().map(|&i| b[i]))
    }

    /// `(c' T)'`.
    fn c(&self, c: &DVector<f64>) -> DVector<f64> {
        DVector::from_fn(self.keep.len(), |j, _| match &self.last {
            Some((l, _)) if self.is_mass(j) => c[self.keep[j]] - c[*l],
            _ => c[self.keep[j]],
        })
    }

    /// `T` (full x kept).
    fn basis(&self, n: usize) -> DMatrix<f64> {
        let m = self.keep.len();
        DMatrix::from_fn(n, m, |i, j| {
            if i == self.keep[j] {
                1.0
            } else if self.last.as_ref().is_some_and(|(l, _)| *l == i) && self.is_mass(j) {
                -1.0
            } else {
                0.0
            }
        })
    }
}

/// The nonzeros of a vector with their indices.
fn nonzeros(v: &DVector<f64>) -> Vec<(usize, f64)> {
    v.iter()
        .enumerate()
        .filter(|(_, x)| **x != 0.0)
        .map(|(i, x)| (i, *x))
        .collect()
}

/// The export of a linearization.
pub fn export(model: &dyn Model, lin: &Linearization) -> StateSpaceExport {
    let ol = &lin.open_loop;
    let names = model.state_names();
    let el = Elimination::new(model);
    let (b, k) = (el.b(&ol.full.b), el.c(&ol.full.k()));
    let input = format!("{} ({})", ol.full.name, ol.full.unit);
    let output = format!("K x, fed back as u = -K x ({})", ol.full.unit);
    // `J` and `A0 = J - b c'` by their nonzeros: the sparse route never forms them dense
    let n = names.len();
    let j: Vec<(usize, usize, f64)> = match &lin.dynamics.sparse {
        Some(sp) => sp.entries.clone(),
        None => entries(&lin.dynamics.jacobian),
    };
    let a0: Vec<(usize, usize, f64)> = if ol.full.a.nrows() == n {
        entries(&ol.full.a)
    } else {
        let (bi, ci) = (nonzeros(&ol.full.b), nonzeros(&ol.full.c));
        let mut a0 = j.clone();
        for &(r, bv) in &bi {
            a0.extend(ci.iter().map(|&(c, cv)| (r, c, -bv * cv)));
        }
        a0
    };
    let mut broken = system(el.a(n, &a0), &b, &k, &ol.poles);
    broken.input = format!("u: {input}");
    broken.output = output.clone();
    let mut closed = system(el.a(n, &j), &b, &k, &lin.dynamics.poles);
    closed.input = format!("disturbance added to {input}");
    closed.output = output;
    let bode = lin.bode();
    StateSpaceExport {
        model: model.name().to_string(),
        n: model.n(),
        closure: model.closure().to_string(),
        convention: CONVENTION.to_string(),
        inventory_reduced: el.last.is_some(),
        reduction: match &el.last {
            Some((l, _)) => format!(
                "`{}` eliminated: its deviation is minus the sum of the other mass deviations (constant charge)",
                names[*l]
            ),
            None => "none: no conserved inventory among the states".into(),
        },
        states: el.keep.iter().map(|&i| names[i].clone()).collect(),
        basis: (el.last.is_some() && names.len() <= DENSE_UP_TO)
            .then(|| rows(&el.basis(names.len()))),
        full_states: names,
        equilibrium: lin.dynamics.equilibrium.x.clone(),
        broken_loop: broken,
        closed_loop: closed,
        bode: BodeData {
            magnitude: bode.mag_db.iter().map(|db| 10f64.powf(db / 20.0)).collect(),
            w_rad_s: bode.w,
            magnitude_db: bode.mag_db,
            phase_deg: bode.phase_deg,
        },
    }
}
