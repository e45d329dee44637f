//! Linear analysis of any generated model (docs/physics.md sections 6-7).
//!
//! The pipeline of [`linearize`](crate::linear::linearize):
//! 1. [`equilibrium`](crate::linear::equilibrium): `f(x*) = 0` by Newton with the analytic Jacobian
//! (mass constraint with `full`);
//! 2. `J = df/dx (x*)` from the generated Jacobian;
//! 3. [`reduce`](crate::linear::reduce): the dynamic part `T' J T` on `ker c` and the inventory
//! mode;
//! 4. [`poles`](crate::linear::poles): the closed-loop poles `eig(T' J T)`;
//! 5. [`loop_break`](crate::linear::loop_break): the loop broken at a pressure-force (or
//! common-pressure) input, `L(s) = K (sI - A0)^-1 B` with `A0 - B K = J`, evaluated by
//! [`response`](crate::linear::response);
//! 6. [`margins`](crate::linear::margins) of `L(jw)` as MATLAB's `margin`, and
//! [`bode`](crate::linear::bode) / Nyquist data.
//!
//! Large models (from [`dynamics::DOMINANT_FROM`](crate::linear::dynamics::DOMINANT_FROM) states)
//! take a sparse route: the Newton system by sparse LU, the dominant poles by shift-invert Arnoldi
//! ([`dominant`](crate::linear::dominant)), `L(jw)` by a sparse solve per frequency on the full
//! state ([`sparse_response`](crate::linear::sparse_response));
//! [`DynamicPoles::route`](crate::linear::DynamicPoles::route) and
//! [`LinearReport::route`](crate::linear::LinearReport::route) say which route was taken.
//!
//! [`locus`](crate::linear::locus) repeats 1-4 over a parameter range.
//! [`LinearReport`](crate::linear::LinearReport) is the serializable summary that `stirling
//! linearize --json` prints.

/// Diagonal balancing (Parlett-Reinsch, radix 2).
pub mod balance;
/// Bode and Nyquist data of `L(jw)` on a frequency grid, and the grid itself.
pub mod bode;
/// The dominant poles of a large model by shift-invert Arnoldi on the sparse Jacobian.
pub mod dominant;
/// Steps 1-4 (equilibrium, Jacobian, reduction, poles) and the choice of route by size.
pub mod dynamics;
/// The equilibrium `f(x*) = 0` by Newton's method with the analytic Jacobian.
pub mod equilibrium;
/// The linear results as control engineers use them.
pub mod export;
/// Root locus over any model parameter.
pub mod locus;
/// Breaking the feedback loop at a pressure-force input (docs/physics.md section 7).
pub mod loop_break;
/// Gain and phase margins of a negative-feedback loop `L(jw)`, as MATLAB's `margin`.
pub mod margins;
/// Eigenvalues of a state matrix as poles.
pub mod poles;
/// Inventory reduction (docs/physics.md section 6).
pub mod reduce;
/// The frequency response `L(s) = K (sI - A)^-1 B` of a single-input single-output triple.
pub mod response;
/// Dense real linear solves `A x = b` by LU with partial pivoting (faer).
pub mod solve;
/// Sparse matrices as triplets and faer sparse LU solves, real and complex-shifted.
pub mod sparse;
/// `L(jw)` of a large model by sparse solves on the full state.
pub mod sparse_response;
#[cfg(test)]
mod tests_sparse;

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

pub use bode::{Bode, Nyquist};
pub use dominant::{dominant_poles, DominantOptions, DominantPoles};
pub use dynamics::{dynamic_poles, dynamic_poles_with, DynamicPoles, PoleRequest, PoleRoute};
pub use equilibrium::{Equilibrium, NewtonOptions};
pub use locus::{Locus, LocusPoint};
pub use loop_break::{Channel, LoopBreak};
pub use margins::{GainMargin, Margins, PhaseMargin};
/// The matrix crate of the public API (`DMatrix`, `DVector`, `Complex`).
pub use nalgebra;
pub use poles::Pole;
pub use reduce::{InventoryMode, Reduction};
pub use response::FrequencyResponse;
pub use sparse_response::{LoopResponse, SparseResponse};

/// Why a linear analysis cannot be done.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinearError {
    #[error("equilibrium: Newton did not converge in {iterations} iterations (scaled residual {residual:.3e} 1/s, tolerance {tol:.1e})")]
    NoConvergence {
        iterations: usize,
        residual: f64,
        tol: f64,
    },
    #[error("equilibrium is not physical: the {quantity} is {value:.4e} there (volumes, pressures, temperatures and masses must be positive); the parameters put the engine outside its working range: check the values you set (e.g. the bounce pressure against the mean pressure, spring rates)")]
    Nonphysical { quantity: String, value: f64 },
    #[error("equilibrium: the Newton system is singular at iteration {iteration}")]
    Singular { iteration: usize },
    #[error("non-finite values in the {what}")]
    NonFinite { what: &'static str },
    #[error("loop channel `{name}` does not exist for model `{model}`; valid channels: {valid}")]
    UnknownChannel {
        name: String,
        model: String,
        valid: String,
    },
    #[error("channel `pressure` needs a single-pressure model; the bodies of `{model}` see different pressures (choose a body channel)")]
    NotSinglePressure { model: String },
    #[error("unknown parameter `{name}` for model `{model}`; valid parameters: {valid}")]
    UnknownParam {
        name: String,
        model: String,
        valid: String,
    },
    #[error("the parameter range is empty (use at least one step)")]
    EmptyRange,
    /// A locus point failed: at which value of the parameter swept.
    #[error("at {param} = {value:e} (point {point} of {points}): {source}; a locus cannot pass this value: sweep a range that ends before it")]
    AtValue {
        param: String,
        value: f64,
        point: usize,
        points: usize,
        source: Box<LinearError>,
    },
    #[error("{0}")]
    Param(String),
    #[error("eigenvalue computation failed: {0}")]
    Eigen(String),
    #[error("dominant poles: no Ritz value converged at any shift; the smallest residual {residual:.3e} was at the shift {shift_re} {shift_im:+}j rad/s")]
    NoDominantPoles {
        shift_re: f64,
        shift_im: f64,
        residual: f64,
    },
    #[error("sparse LU of the Jacobian shifted by {shift_re} {shift_im:+}j rad/s failed: {why}")]
    ShiftFactor {
        shift_re: f64,
        shift_im: f64,
        why: String,
    },
}

/// Settings of [`linearize`].
#[derive(Clone, Debug, PartialEq)]
pub struct LinearOptions {
    /// Loop channel by name (`pressure` or a body); `None`: [`loop_break::default_channel`].
    pub channel: Option<String>,
    pub newton: NewtonOptions,
    /// Grid density for crossovers and Bode data (points per decade).
    pub per_decade: usize,
    /// All poles (dense) or the dominant ones (sparse); by size unless asked.
    pub poles: PoleRequest,
}

impl Default for LinearOptions {
    fn default() -> Self {
        Self {
            channel: None,
            newton: NewtonOptions::default(),
            per_decade: 100,
            poles: PoleRequest::Auto,
        }
    }
}

/// The loop broken at one channel, reduced on the inventory.
#[derive(Clone, Debug)]
pub struct OpenLoop {
    /// The triple in full state coordinates.
    pub full: LoopBreak,
    /// `T' A0 T` (empty on the sparse route), `T' B`, `K T` (the full triple without mass states).
    pub a: DMatrix<f64>,
    pub b: DVector<f64>,
    pub k: DVector<f64>,
    /// Poles of the open loop (`eig A0`), sorted: all, or the dominant ones on the sparse route.
    pub poles: Vec<Pole>,
    pub response: LoopResponse,
}

impl OpenLoop {
    /// `L(jw)`.
    pub fn at(&self, w: f64) -> nalgebra::Complex<f64> {
        self.response.at(w)
    }
}

/// The complete linear analysis.
#[derive(Clone, Debug)]
pub struct Linearization {
    pub dynamics: DynamicPoles,
    pub open_loop: OpenLoop,
    /// The grid the margins were bracketed on.
    pub grid: Vec<f64>,
    /// `L(jw)` on the grid, evaluated once (each value is a solve with the shifted Jacobian:
    /// at n = 10,000 sections the Bode data of `--json` doubled the run when evaluated again).
    pub grid_values: Vec<nalgebra::Complex<f64>>,
    pub margins: Margins,
}

/// The whole pipeline.
pub fn linearize(
    model: &dyn Model,
    p: &[f64],
    opts: &LinearOptions,
) -> Result<Linearization, LinearError> {
    let dynamics = dynamic_poles_with(model, p, &opts.newton, opts.poles)?;
    let x = &dynamics.equilibrium.x;
    let channel = match &opts.channel {
        Some(name) => loop_break::parse_channel(model, p, x, name)?,
        None => loop_break::default_channel(model, p, x),
    };
    let open_loop = match &dynamics.sparse {
        None => dense_open_loop(model, p, &dynamics, channel)?,
        Some(j) => sparse_open_loop(model, p, &dynamics, j, channel)?,
    };
    let all: Vec<Pole> = dynamics
        .poles
        .iter()
        .chain(&open_loop.poles)
        .copied()
        .collect();
    let per_decade = if model.n_states() > 400 {
        opts.per_decade.min(20)
    } else {
        opts.per_decade
    };
    let grid = bode::frequency_grid(&all, per_decade);
    let grid_values: Vec<nalgebra::Complex<f64>> = grid.iter().map(|&w| open_loop.at(w)).collect();
    let on_grid = |w: f64| match grid.binary_search_by(|g| g.total_cmp(&w)) {
        Ok(k) => grid_values[k],
        Err(_) => open_loop.at(w),
    };
    let margins = margins::margins(&on_grid, &grid);
    Ok(Linearization {
        dynamics,
        open_loop,
        grid,
        grid_values,
        margins,
    })
}

fn dense_open_loop(
    model: &dyn Model,
    p: &[f64],
    dynamics: &DynamicPoles,
    channel: Channel,
) -> Result<OpenLoop, LinearError> {
    let x = &dynamics.equilibrium.x;
    let full = loop_break::break_loop(model, p, x, &dynamics.jacobian, channel)?;
    let red = &dynamics.reduction;
    let (a, b, k) = (
        red.reduce(&full.a),
        red.project(&full.b),
        red.project(&full.k()),
    );
    let poles = poles::poles(&a)?;
    let response = LoopResponse::Dense(FrequencyResponse::new(&a, &b, &k));
    Ok(OpenLoop {
        full,
        a,
        b,
        k,
        poles,
        response,
    })
}

/// The open loop of a large model: `A0 = J - B C` stays sparse, its dominant poles by the same
/// route as the closed loop's, `L(jw)` by sparse solves.
fn sparse_open_loop(
    model: &dyn Model,
    p: &[f64],
    dynamics: &DynamicPoles,
    j: &sparse::SparseMatrix,
    channel: Channel,
) -> Result<OpenLoop, LinearError> {
    let x = &dynamics.equilibrium.x;
    let full = loop_break::break_loop_input(model, p, x, channel)?;
    let (scales, masses) = (
        equilibrium::state_scales(model, x),
        equilibrium::mass_states(model),
    );
    let response = SparseResponse::new(j, &full.b, &full.c, &scales, &masses)?;
    let neg_b: Vec<f64> = full.b.iter().map(|v| -v).collect();
    let c: Vec<f64> = full.c.iter().copied().collect();
    let a0 = j.plus_outer(&neg_b, &c);
    let k = match &dynamics.route {
        PoleRoute::SparseDominant { k, .. } => *k,
        PoleRoute::Dense => dynamics::DOMINANT_K,
    };
    let opts = DominantOptions {
        k,
        ..Default::default()
    };
    let poles = dominant::dominant_poles_with(&a0, &scales, &masses, &opts)?.poles;
    let red = &dynamics.reduction;
    Ok(OpenLoop {
        b: red.project(&full.b),
        k: red.project(&full.k()),
        full,
        a: DMatrix::zeros(0, 0),
        poles,
        response: LoopResponse::Sparse(Box::new(response)),
    })
}

impl Linearization {
    /// Bode data of `L(jw)` on the analysis grid.
    pub fn bode(&self) -> Bode {
        bode::bode(&|w| self.on_grid(w), &self.grid)
    }

    /// Nyquist data of `L(jw)` on the analysis grid.
    pub fn nyquist(&self) -> Nyquist {
        bode::nyquist(&|w| self.on_grid(w), &self.grid)
    }

    /// `L(jw)`: the stored value on the grid, else evaluated.
    fn on_grid(&self, w: f64) -> nalgebra::Complex<f64> {
        match self.grid.binary_search_by(|g| g.total_cmp(&w)) {
            Ok(k) if k < self.grid_values.len() => self.grid_values[k],
            _ => self.open_loop.at(w),
        }
    }

    /// The serializable summary.
    pub fn report(&self, model: &dyn Model) -> LinearReport {
        let ol = &self.open_loop;
        LinearReport {
            model: model.name().to_string(),
            n: model.n(),
            closure: model.closure().to_string(),
            n_states: model.n_states(),
            state_names: model.state_names(),
            equilibrium: self.dynamics.equilibrium.clone(),
            poles: self.dynamics.poles.clone(),
            route: self.dynamics.route.clone(),
            rhp_count: self.dynamics.poles.iter().filter(|p| p.rhp).count(),
            inventory_mode: self.dynamics.reduction.inventory.clone(),
            loop_break: LoopReport {
                channel: ol.full.name.clone(),
                unit: ol.full.unit.to_string(),
                b: ol.full.b.iter().copied().collect(),
                k: ol.full.k().iter().copied().collect(),
                open_loop_poles: ol.poles.clone(),
                open_loop_rhp_count: ol.poles.iter().filter(|p| p.rhp).count(),
            },
            margins: self.margins.clone(),
        }
    }
}

/// The loop as reported: `x' = A0 x + B u`, `u = -K x`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoopReport {
    /// `pressure` or the body name.
    pub channel: String,
    /// Unit of `u`.
    pub unit: String,
    /// Input column `B` (full state order).
    pub b: Vec<f64>,
    /// Feedback gain `K` (full state order).
    pub k: Vec<f64>,
    pub open_loop_poles: Vec<Pole>,
    pub open_loop_rhp_count: usize,
}

/// What `stirling linearize --json` prints.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearReport {
    pub model: String,
    pub n: usize,
    pub closure: String,
    pub n_states: usize,
    pub state_names: Vec<String>,
    pub equilibrium: Equilibrium,
    /// Closed-loop (dynamic) poles, sorted by decreasing real part.
    pub poles: Vec<Pole>,
    /// How the poles were computed (dense: all; sparse: the dominant ones).
    pub route: PoleRoute,
    /// Right-half-plane poles among `poles`.
    pub rhp_count: usize,
    pub inventory_mode: Option<InventoryMode>,
    #[serde(rename = "loop")]
    pub loop_break: LoopReport,
    pub margins: Margins,
}
