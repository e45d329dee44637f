//! The core of `examples/nsection_matrix.rs` (also run by `tests/nsection_matrix.rs`):
//! `nsection` with a regenerator matrix of finite heat capacity, declared by extending the
//! family's `nsection_engine`, against the fixed-wall `nsection` and the seed's 8th-order
//! model (`nsection` with two sections, alias `order8`).
#![allow(dead_code)] // the test uses a part of it

use stirling::dsl::{Closure, Model};
use stirling::models::family::NSection;
use stirling::models::linear::{self, LinearError, NewtonOptions};
use stirling::models::sim::{self, SimError, SimOptions, SimSummary};
use stirling::stirling_model;

stirling_model! {
    /// `nsection` whose regenerator wall is a matrix of heat capacity `1/km` (J/K, whole
    /// matrix), section `j` behind `regen[j]`, with axial conduction `Gm` along the matrix and to
    /// the heater and cooler ends (so the linear rest profile is the unique equilibrium).
    pub model NSectionMatrix extends stirling::models::nsection_engine {
        name "nsection_matrix";
        params {
            /// inverse heat capacity of the whole matrix (0: infinite, the fixed wall)
            km: 0.0 "K/J",
            /// axial conductance of the whole matrix
            Gm: 0.03 "W/K",
        }
        modify cv regen { port wall { h: hr, area: Awr / n, wall: matrix[j] } }
        wall matrix[n] { capacity: 1.0 / (km * n), rest: Th - (j + 0.5) * (Th - Tk) / n }
        link matrix[j] -> matrix[j + 1] for j in 0..n - 1 { conductance: Gm * n }
        link Th -> matrix[0] { conductance: 2.0 * Gm * n }
        link matrix[n - 1] -> Tk { conductance: 2.0 * Gm * n }
    }
}

/// Why a study case fails.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("model: {0}")]
    Model(#[from] stirling::dsl::ModelError),
    #[error("equilibrium or poles: {0}")]
    Linear(#[from] LinearError),
    #[error("limit cycle: {0}")]
    Sim(#[from] SimError),
    #[error("{0}: no oscillating pole pair")]
    NoPair(String),
    #[error("{0}: the run did not settle on a limit cycle")]
    NoCycle(String),
}

/// What one model does: its dominant pole pair and its limit cycle.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Case {
    pub label: String,
    /// Matrix heat capacity (J/K; `None`: infinite, the fixed wall).
    pub capacity: Option<f64>,
    pub n_states: usize,
    /// The dominant (rightmost oscillating) pole `re + i im` (1/s, rad/s).
    pub pole: (f64, f64),
    pub frequency_hz: f64,
    /// Displacer and piston strokes, peak to peak (m).
    pub x_stroke: f64,
    pub y_stroke: f64,
    /// Indicated power (W).
    pub power_w: f64,
}

/// The dominant pole pair: the rightmost pole with a positive imaginary part.
fn dominant(model: &dyn Model, p: &[f64], label: &str) -> Result<(f64, f64), StudyError> {
    let d = linear::dynamic_poles(model, p, &NewtonOptions::default())?;
    d.poles
        .iter()
        .filter(|q| q.im > 0.0)
        .map(|q| (q.re, q.im))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or_else(|| StudyError::NoPair(label.into()))
}

/// Poles and limit cycle of `model` at `p` (settled over at most `t_max` s from the
/// equilibrium with the displacer 1 mm off).
pub fn case(
    model: &dyn Model,
    p: &[f64],
    label: &str,
    capacity: Option<f64>,
    t_max: f64,
) -> Result<Case, StudyError> {
    eprintln!("{label} ...");
    let pole = dominant(model, p, label)?;
    let eq = linear::equilibrium::solve(model, p, &NewtonOptions::default())?;
    let mut x0 = eq.x.clone();
    x0[0] += 1e-3;
    let samples = sim::uniform_samples(t_max, 4000);
    let lc = sim::limit_cycle(model, p, &x0, t_max, &samples, &SimOptions::default(), None)?;
    let s = SimSummary::from_run(model, &lc.settled.trajectory).with_cycle(&lc);
    let none = || StudyError::NoCycle(label.into());
    Ok(Case {
        label: label.into(),
        capacity,
        n_states: model.n_states(),
        pole,
        frequency_hz: s.frequency_hz.ok_or_else(none)?,
        x_stroke: 2.0 * s.x_amp.ok_or_else(none)?,
        y_stroke: 2.0 * s.y_amp.ok_or_else(none)?,
        power_w: s.power_w.ok_or_else(none)?,
    })
}

/// The matrix model at `n` with heat capacity `capacity` J/K (`km = 1/capacity`).
pub fn matrix_case(n: usize, capacity: f64, t_max: f64) -> Result<Case, StudyError> {
    let m = NSectionMatrix::new(n, Closure::Full)?;
    let mut p = m.default_params();
    p[m.param_index("km").expect("declared")] = 1.0 / capacity;
    // the matrix's thermal time constant C / (hr Awr): let it settle (within 60 s)
    let tau = capacity / (100.0 * 0.0377);
    let t = (t_max + 4.0 * tau).min(60.0f64.max(t_max));
    case(
        &m,
        &p,
        &format!("matrix {capacity:e} J/K"),
        Some(capacity),
        t,
    )
}

/// The fixed-wall `nsection` at `n` (label `label`).
pub fn fixed_case(n: usize, label: &str, t_max: f64) -> Result<Case, StudyError> {
    let m = NSection::new(n, Closure::Full)?;
    case(&m, &m.default_params(), label, None, t_max)
}

/// The study: the 8th-order baseline, the fixed wall at `n`, then each capacity.
pub fn study(n: usize, capacities: &[f64], t_max: f64) -> Result<Vec<Case>, StudyError> {
    let mut out = vec![
        fixed_case(2, "8th order (nsection n=2, fixed wall)", t_max)?,
        fixed_case(
            n,
            &format!("nsection n={n}, fixed wall (infinite C)"),
            t_max,
        )?,
    ];
    for &c in capacities {
        out.push(matrix_case(n, c, t_max)?);
    }
    Ok(out)
}
