//! Steps 1-4 of [`crate::linear::linearize`]: equilibrium, Jacobian, inventory reduction and poles,
//! by one of two routes chosen by size
//! ([`PoleRequest::Auto`](crate::linear::dynamics::PoleRequest::Auto)):
//!
//! - **dense** (up to [`DOMINANT_FROM`](crate::linear::dynamics::DOMINANT_FROM)` - 1` states, or
//!   when all poles are asked for): the dense Jacobian, `T' J T` and all its eigenvalues
//!   ([`crate::linear::poles`]);
//! - **sparse dominant** (from [`DOMINANT_FROM`](crate::linear::dynamics::DOMINANT_FROM) states):
//!   the Jacobian as triplets, the equilibrium by the sparse Newton, and the rightmost poles by
//!   shift-invert Arnoldi ([`crate::linear::dominant`]); `jacobian` and `reduction.a` are then
//!   empty (`0 x 0`).

use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use super::dominant::{dominant_poles_with, DominantOptions};
use super::equilibrium::{self, mass_states, state_scales, Equilibrium, NewtonOptions};
use super::poles::{self, Pole};
use super::reduce::{self, Reduction};
use super::sparse::SparseMatrix;
use super::LinearError;

/// The smallest state count that takes the sparse dominant route under [`PoleRequest::Auto`].
pub const DOMINANT_FROM: usize = 401;
/// Dominant poles kept by [`PoleRequest::Auto`] on the sparse route.
pub const DOMINANT_K: usize = 5;

/// Which poles are wanted.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PoleRequest {
    /// All poles below [`DOMINANT_FROM`] states, the [`DOMINANT_K`] dominant ones from there on.
    #[default]
    Auto,
    /// All poles, dense, at any size.
    All,
    /// The `k` rightmost poles by the sparse route, at any size.
    Dominant(usize),
}

/// How the poles were computed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum PoleRoute {
    /// All eigenvalues of the dense reduced Jacobian.
    Dense,
    /// The `k` rightmost poles by shift-invert Arnoldi on the sparse Jacobian.
    SparseDominant {
        k: usize,
        /// The shifts `(re, im)` used (scan, then refinement).
        shifts: Vec<(f64, f64)>,
        /// Arnoldi steps (sparse solves) over all shifts.
        iterations: usize,
        /// Largest relative Ritz residual of the returned poles.
        residual: f64,
    },
}

impl PoleRoute {
    /// One line for the text report.
    pub fn describe(&self, n_states: usize) -> String {
        match self {
            Self::Dense => format!("dense: all eigenvalues of the {n_states}-state Jacobian, reduced"),
            Self::SparseDominant { k, shifts, iterations, residual } => format!(
                "sparse dominant: the {k} rightmost by shift-invert Arnoldi ({} shifts, {iterations} sparse solves, Ritz residual {residual:.1e}); all poles: --all-poles",
                shifts.len()
            ),
        }
    }
}

/// Equilibrium, Jacobian, reduction and poles: steps 1-4 of the pipeline.
#[derive(Clone, Debug)]
pub struct DynamicPoles {
    pub equilibrium: Equilibrium,
    /// The full Jacobian at the equilibrium (empty on the sparse route: see `sparse`).
    pub jacobian: DMatrix<f64>,
    /// The Jacobian as triplets (sparse route only).
    pub sparse: Option<SparseMatrix>,
    pub reduction: Reduction,
    /// Poles of the reduced Jacobian, sorted: all of them (dense) or the dominant ones.
    pub poles: Vec<Pole>,
    pub route: PoleRoute,
}

impl DynamicPoles {
    /// The full Jacobian, dense (built from the triplets on the sparse route).
    pub fn dense_jacobian(&self) -> DMatrix<f64> {
        match &self.sparse {
            Some(s) => {
                let mut m = DMatrix::zeros(s.n, s.n);
                for &(i, j, v) in &s.entries {
                    m[(i, j)] += v;
                }
                m
            }
            None => self.jacobian.clone(),
        }
    }
}

/// Steps 1-4 with the route chosen by size ([`PoleRequest::Auto`]).
pub fn dynamic_poles(
    model: &dyn Model,
    p: &[f64],
    newton: &NewtonOptions,
) -> Result<DynamicPoles, LinearError> {
    dynamic_poles_with(model, p, newton, PoleRequest::Auto)
}

/// Steps 1-4 by the route `request` asks for.
pub fn dynamic_poles_with(
    model: &dyn Model,
    p: &[f64],
    newton: &NewtonOptions,
    request: PoleRequest,
) -> Result<DynamicPoles, LinearError> {
    let n = model.n_states();
    let k = match request {
        PoleRequest::All => None,
        PoleRequest::Auto if n < DOMINANT_FROM => None,
        PoleRequest::Auto => Some(DOMINANT_K),
        PoleRequest::Dominant(k) => Some(k),
    };
    let equilibrium = equilibrium::solve(model, p, newton)?;
    match k {
        None => dense(model, p, equilibrium),
        Some(k) => sparse(model, p, equilibrium, k),
    }
}

fn dense(
    model: &dyn Model,
    p: &[f64],
    equilibrium: Equilibrium,
) -> Result<DynamicPoles, LinearError> {
    let n = model.n_states();
    let jacobian = DMatrix::from_vec(n, n, model.jacobian_dense(p, &equilibrium.x, 0.0));
    let reduction = reduce::reduce(&jacobian, &mass_states(model));
    let poles = poles::poles(&reduction.a)?;
    Ok(DynamicPoles {
        equilibrium,
        jacobian,
        sparse: None,
        reduction,
        poles,
        route: PoleRoute::Dense,
    })
}

fn sparse(
    model: &dyn Model,
    p: &[f64],
    equilibrium: Equilibrium,
    k: usize,
) -> Result<DynamicPoles, LinearError> {
    let x = &equilibrium.x;
    let j = SparseMatrix {
        n: x.len(),
        entries: model.jacobian_triplets(p, x, 0.0),
    };
    let masses = mass_states(model);
    let opts = DominantOptions {
        k,
        ..Default::default()
    };
    let d = dominant_poles_with(&j, &state_scales(model, x), &masses, &opts)?;
    let reduction = reduce::reduce_sparse(&j, &masses);
    Ok(DynamicPoles {
        equilibrium,
        jacobian: DMatrix::zeros(0, 0),
        sparse: Some(j),
        reduction,
        poles: d.poles,
        route: PoleRoute::SparseDominant {
            k,
            shifts: d.shifts,
            iterations: d.iterations,
            residual: d.residual,
        },
    })
}
