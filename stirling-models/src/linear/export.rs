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
//! = T z`.
//!
//! Size: from [`SPARSE_FROM`](crate::linear::export::SPARSE_FROM) states on `A`, `B`, `C`, `D`
//! and `T` are also written as triplets (`a_sparse`, `b_sparse`, `c_sparse`, `d_sparse`,
//! `basis_sparse`; 0-based, row-major, each stating
//! [`FORMAT`](crate::linear::export::FORMAT)), above
//! [`DENSE_UP_TO`](crate::linear::export::DENSE_UP_TO) only so (the dense fields are `null`).
//! Nothing is built dense then: `A` comes from the Jacobian's nonzeros (the sparse route's
//! triplets), the broken loop's `A0 = J - B C` adds the rank-one product of the nonzeros of `B`
//! and `C`, and the elimination (a private module) works on nonzeros too. (On the dense route,
//! below 401 states or with `--all-poles`, the linearization holds `J` dense already and its
//! nonzeros are read from it.) Below 200 states the file is as before: `a_sparse` is `null` and
//! no other sparse field is written.

mod elimination;
mod triplets;

use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use self::elimination::Elimination;
pub use self::triplets::{Triplets, FORMAT};
use super::{Linearization, Pole};

/// The largest state count written as dense matrices.
pub const DENSE_UP_TO: usize = 500;
/// The smallest state count also written as triplets.
pub const SPARSE_FROM: usize = 200;

/// The sign convention, in words.
pub const CONVENTION: &str = "x' = A x + B u, y = C x + D u; the loop closes with negative unity feedback u = -y, so closed_loop.a = broken_loop.a - B C; margins of broken_loop as MATLAB's margin and python-control's control.margin";

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

/// A single-input single-output state-space system. Up to [`DENSE_UP_TO`] states `a, b, c, d`
/// are dense; from [`SPARSE_FROM`] states on the same matrices are also written as triplets
/// (`a_sparse`, `b_sparse`, ...); above [`DENSE_UP_TO`] only so (the dense fields are `null`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StateSpace {
    /// `A` by rows.
    pub a: Option<Vec<Vec<f64>>>,
    /// `A` as triplets.
    pub a_sparse: Option<Triplets>,
    /// `B`, one column.
    pub b: Option<Vec<Vec<f64>>>,
    /// `B` as triplets (`n x 1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b_sparse: Option<Triplets>,
    /// `C`, one row.
    pub c: Option<Vec<Vec<f64>>>,
    /// `C` as triplets (`1 x n`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub c_sparse: Option<Triplets>,
    /// `D` (1 x 1).
    pub d: Option<Vec<Vec<f64>>>,
    /// `D` as triplets (`1 x 1`, no entry: zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d_sparse: Option<Triplets>,
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
    /// `T` as triplets (from [`SPARSE_FROM`] states on, with reduction).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub basis_sparse: Option<Triplets>,
    pub broken_loop: StateSpace,
    pub closed_loop: StateSpace,
    pub bode: BodeData,
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

/// A matrix of `n` states (rows of `A`, `B`; columns of `C`; `T`) as the export writes it: dense
/// up to [`DENSE_UP_TO`], triplets from [`SPARSE_FROM`].
fn forms(n: usize, t: Triplets) -> (Option<Vec<Vec<f64>>>, Option<Triplets>) {
    (
        (n <= DENSE_UP_TO).then(|| t.dense_rows()),
        (n >= SPARSE_FROM).then_some(t),
    )
}

fn system(a: Triplets, b: &DVector<f64>, c: &DVector<f64>, poles: &[Pole]) -> StateSpace {
    let n = a.rows;
    let (a, a_sparse) = forms(n, a);
    // dense `b`, `c` straight from the vectors (their signed zeros kept, as before triplets)
    let dense = n <= DENSE_UP_TO;
    let b_dense = dense.then(|| b.iter().map(|v| vec![*v]).collect());
    let c_dense = dense.then(|| vec![c.iter().copied().collect()]);
    let b_sparse = (n >= SPARSE_FROM).then(|| Triplets::column(b));
    let c_sparse = (n >= SPARSE_FROM).then(|| Triplets::row(c));
    let (d, d_sparse) = forms(n, Triplets::new(1, 1));
    StateSpace {
        a,
        a_sparse,
        b: b_dense,
        b_sparse,
        c: c_dense,
        c_sparse,
        d,
        d_sparse,
        input: String::new(),
        output: String::new(),
        poles: damp(poles),
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

/// The nonzeros of the full `J` and `A0 = J - B C`: the sparse route never forms them dense, and
/// `B C` is a rank-one update of the nonzeros of `B` times those of `C`.
fn jacobian_and_open_loop(lin: &Linearization, n: usize) -> (Entries, Entries) {
    let ol = &lin.open_loop.full;
    let j: Entries = match &lin.dynamics.sparse {
        Some(sp) => sp.entries.clone(),
        None => Triplets::of_dense(&lin.dynamics.jacobian)
            .entries()
            .collect(),
    };
    if ol.a.nrows() == n {
        return (j, Triplets::of_dense(&ol.a).entries().collect());
    }
    let (bi, ci) = (nonzeros(&ol.b), nonzeros(&ol.c));
    let mut a0 = j.clone();
    for &(r, bv) in &bi {
        a0.extend(ci.iter().map(|&(c, cv)| (r, c, -bv * cv)));
    }
    (j, a0)
}

/// Matrix nonzeros `(i, j, v)`, 0-based.
type Entries = Vec<(usize, usize, f64)>;

/// The export of a linearization.
pub fn export(model: &dyn Model, lin: &Linearization) -> StateSpaceExport {
    let ol = &lin.open_loop;
    let names = model.state_names();
    let n = names.len();
    let el = Elimination::new(model);
    let (b, k) = (el.b(&ol.full.b), el.c(&ol.full.k()));
    let input = format!("{} ({})", ol.full.name, ol.full.unit);
    let output = format!("K x, fed back as u = -K x ({})", ol.full.unit);
    let (j, a0) = jacobian_and_open_loop(lin, n);
    let mut broken = system(el.a(n, &a0), &b, &k, &ol.poles);
    broken.input = format!("u: {input}");
    broken.output = output.clone();
    let mut closed = system(el.a(n, &j), &b, &k, &lin.dynamics.poles);
    closed.input = format!("disturbance added to {input}");
    closed.output = output;
    let (basis, basis_sparse) = match el.last {
        Some(_) => forms(n, el.basis(n)),
        None => (None, None),
    };
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
        basis,
        basis_sparse,
        full_states: names,
        equilibrium: lin.dynamics.equilibrium.x.clone(),
        broken_loop: broken,
        closed_loop: closed,
        bode: bode_data(lin),
    }
}

fn bode_data(lin: &Linearization) -> BodeData {
    let bode = lin.bode();
    BodeData {
        magnitude: bode.mag_db.iter().map(|db| 10f64.powf(db / 20.0)).collect(),
        w_rad_s: bode.w,
        magnitude_db: bode.mag_db,
        phase_deg: bode.phase_deg,
    }
}
