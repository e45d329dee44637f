//! One point of a sweep: the parameters with the swept values and ties applied, the
//! equilibrium's dominant pole, and, where the engine is unstable at rest, the limit cycle it
//! settles on. A point that fails is recorded with its error; it never stops the sweep.

use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use super::grid::{Axis, Tie};
use crate::layout::StateLayout;
use crate::linear::{self, LinearError, NewtonOptions};
use crate::params::{self, ParamError};
use crate::sim::{self, SimOptions};

/// What became of a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Right-half-plane poles at rest and a limit cycle with positive work: the engine runs.
    Runs,
    /// Every pole in the left half plane: the engine stays at rest.
    Stable,
    /// Unstable at rest, but no limit cycle with positive work was found.
    UnstableNoCycle,
    /// Unstable at rest; the limit cycle was not asked for (`cycles: false`).
    Unstable,
    /// The parameters are unphysical or a solver failed (see `error`).
    Failed,
}

/// The result of one point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointResult {
    /// Index in the full grid (shards keep it, so that merged slices sort back).
    pub index: usize,
    /// The swept values, in axis order.
    pub values: Vec<f64>,
    pub outcome: Outcome,
    /// Right-half-plane poles of the reduced Jacobian at rest.
    pub rhp: Option<usize>,
    /// The dominant pole (largest real part): growth rate (1/s) and frequency (Hz).
    pub growth_rate: Option<f64>,
    pub pole_hz: Option<f64>,
    /// The limit cycle: frequency (Hz), strokes (peak to peak, m), the displacer's phase
    /// ahead of the piston (deg), gas work per cycle (J) and power (W).
    pub frequency_hz: Option<f64>,
    pub x_stroke: Option<f64>,
    pub y_stroke: Option<f64>,
    pub phase_deg: Option<f64>,
    pub work_j: Option<f64>,
    pub power_w: Option<f64>,
    pub error: Option<String>,
}

/// Why a point failed (recorded in its result, as text in the CSV and JSON).
#[derive(Debug, thiserror::Error)]
pub enum PointError {
    #[error(transparent)]
    Params(#[from] ParamError),
    #[error("equilibrium or poles: {0}")]
    Poles(#[from] LinearError),
}

/// How a point is evaluated.
pub struct Evaluate<'a> {
    pub model: &'a dyn Model,
    /// The base parameters (defaults with the user's file and overrides).
    pub base: &'a [f64],
    pub axes: &'a [Axis],
    pub ties: &'a [Tie],
    /// Longest settling time of the limit cycle (s); `None`: poles only.
    pub settle: Option<f64>,
    pub sim: SimOptions,
}

impl Evaluate<'_> {
    /// The parameter vector at the swept `values`, ties applied (a follower keeps its ratio
    /// to its leader).
    pub fn params(&self, values: &[f64]) -> Vec<f64> {
        let mut p = self.base.to_vec();
        let idx = |n: &str| self.model.param_index(n).expect("checked by the sweep");
        for (a, v) in self.axes.iter().zip(values) {
            p[idx(&a.name)] = *v;
        }
        for t in self.ties {
            let (f, l) = (idx(&t.follower), idx(&t.leader));
            p[f] = self.base[f] * p[l] / self.base[l];
        }
        p
    }

    /// Evaluate point `index` at `values`.
    pub fn point(&self, index: usize, values: Vec<f64>) -> PointResult {
        let mut r = PointResult {
            index,
            values,
            outcome: Outcome::Failed,
            rhp: None,
            growth_rate: None,
            pole_hz: None,
            frequency_hz: None,
            x_stroke: None,
            y_stroke: None,
            phase_deg: None,
            work_j: None,
            power_w: None,
            error: None,
        };
        if let Err(e) = self.fill(&mut r) {
            r.outcome = Outcome::Failed;
            r.error = Some(e.to_string());
        }
        r
    }

    /// Poles, then the cycle where the engine is unstable at rest.
    fn fill(&self, r: &mut PointResult) -> Result<(), PointError> {
        let p = self.params(&r.values);
        params::validate(self.model, &p)?;
        let d = linear::dynamic_poles(self.model, &p, &NewtonOptions::default())?;
        let dominant = d.poles.iter().max_by(|a, b| a.re.total_cmp(&b.re));
        r.rhp = Some(d.poles.iter().filter(|q| q.rhp).count());
        r.growth_rate = dominant.map(|q| q.growth_rate);
        r.pole_hz = dominant.map(|q| q.freq_hz);
        if r.rhp == Some(0) {
            r.outcome = Outcome::Stable;
            return Ok(());
        }
        let Some(settle) = self.settle else {
            r.outcome = Outcome::Unstable;
            return Ok(());
        };
        let x0 = self.start(&d.equilibrium.x);
        match sim::limit_cycle(self.model, &p, &x0, settle, &[], &self.sim, None) {
            Ok(lc) => {
                let f = &lc.figures;
                r.frequency_hz = Some(f.frequency_hz);
                r.x_stroke = Some(2.0 * f.x_amp);
                r.y_stroke = Some(2.0 * f.y_amp);
                r.phase_deg = Some(f.phase_deg);
                r.work_j = Some(lc.work.total);
                r.power_w = Some(lc.work.total * f.frequency_hz);
                r.outcome = if lc.work.total > 0.0 {
                    Outcome::Runs
                } else {
                    Outcome::UnstableNoCycle
                };
            }
            Err(e) => {
                r.outcome = Outcome::UnstableNoCycle;
                r.error = Some(format!("limit cycle: {e}"));
            }
        }
        Ok(())
    }

    /// The rest state with the displacer moved by 5 mm (as `stirling simulate` starts).
    fn start(&self, rest: &[f64]) -> Vec<f64> {
        let mut x = rest.to_vec();
        if let Some(&i) = StateLayout::of(self.model).positions.first() {
            x[i] += 5e-3;
        }
        x
    }
}
