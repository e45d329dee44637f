//! The interface every generated model implements; the analyses are generic over it.

use super::jac_sink::JacSink;
use crate::expr::Style;
use crate::Closure;

/// A model parameter as declared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamInfo {
    pub name: &'static str,
    pub default: f64,
    pub unit: &'static str,
    pub doc: &'static str,
    /// The range a fit keeps it in, as declared (`kd: 650.0 "N/m" in 100.0..2000.0`); `None`:
    /// the fit's default (a positive parameter stays above 2 % of its start).
    pub bounds: Option<(f64, f64)>,
}

/// What a state is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateKind {
    /// Position of body `k`.
    Position(usize),
    /// Velocity of body `k`.
    Velocity(usize),
    /// Pressure of CV element `k` (vessel order, arrays expanded).
    Pressure(usize),
    /// Gas mass of CV element `k`.
    Mass(usize),
    /// Temperature of wall element `k` (declaration order, arrays expanded).
    WallTemperature(usize),
}

/// One state with its meaning.
#[derive(Clone, Debug, PartialEq)]
pub struct StateInfo {
    pub name: String,
    pub kind: StateKind,
    pub unit: &'static str,
    pub meaning: String,
}

/// A measured channel declared with the model: the CSV column `name`, in `unit`, observes
/// the state `state` (as [`Model::states`] names it; `sensor p: P_cold "Pa";`) or the
/// expression `expr` of the states `reads` and the parameters (`sensor dp: P_cold - P_bounce
/// "Pa";`, evaluated by [`Model::sensor_output`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SensorInfo {
    pub name: &'static str,
    /// The observed state; empty for an expression sensor.
    pub state: &'static str,
    /// The expression as printed; empty for a state sensor.
    pub expr: &'static str,
    /// The states the output reads, in the order [`Model::sensor_output`] takes their values
    /// (a state sensor: its state).
    pub reads: &'static [&'static str],
    pub unit: &'static str,
}

impl SensorInfo {
    /// What the sensor reads, as declared: its state or its expression.
    pub fn definition(&self) -> &'static str {
        if self.expr.is_empty() {
            self.state
        } else {
            self.expr
        }
    }
}

/// An effect applied to the model where it names it (`effect coulomb on piston;`), at its
/// null: what the diagnosis may test on this model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EffectSite {
    /// The effect (`coulomb`, `end_stops`, `leak`).
    pub effect: &'static str,
    /// Where it acts, as written (`piston`, `cold -> bounce`).
    pub at: &'static str,
    /// Its parameters, the strength first.
    pub params: &'static [&'static str],
}

/// A body of the topology.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BodyInfo {
    pub name: &'static str,
    pub pos: &'static str,
    pub vel: &'static str,
}

/// Energy-rate terms of the budget (docs/physics.md section 10):
/// `dE/dt = heat + boundary + mechanical`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PowerTerms {
    /// Heat from outside the system: through the gas ports to fixed wall temperatures, the
    /// walls' inputs and the conduction from fixed temperatures into walls (heat exchanged
    /// between the gas and a declared wall stays inside).
    pub heat: f64,
    /// Work and enthalpy from given-pressure spaces (`Pb dVb/dt`).
    pub boundary: f64,
    /// Power of dampers and extra forces (negative: dissipation).
    pub mechanical: f64,
}

/// A generated model at a given `n` and closure.
///
/// Callback shape: `(p, x, t, out)`, parameters as a slice in [`Model::params`] order.
pub trait Model: Send + Sync {
    /// The declared model name.
    fn name(&self) -> &'static str;
    /// Number of array sections (1 when the topology has no array).
    fn n(&self) -> usize;
    /// The inventory closure.
    fn closure(&self) -> Closure;
    /// Whether the topology has an array of CVs (so `n` matters).
    fn has_array(&self) -> bool;
    /// Declared parameters, in slice order.
    fn params(&self) -> &'static [ParamInfo];
    /// The bodies, in state order.
    fn bodies(&self) -> &'static [BodyInfo];
    /// Number of states.
    fn n_states(&self) -> usize;
    /// The states, in order.
    fn states(&self) -> Vec<StateInfo>;
    /// Names of the gas vessels (CV elements, then spaces) used by [`Model::pv`].
    fn vessel_names(&self) -> Vec<String>;
    /// `out = f(x, p, t)`.
    fn rhs(&self, p: &[f64], x: &[f64], t: f64, out: &mut [f64]);
    /// The analytic Jacobian `df/dx`.
    fn jacobian(&self, p: &[f64], x: &[f64], t: f64, sink: &mut JacSink);
    /// `out = f(x, p, t)` and the analytic Jacobian `df/dx` in one call, for solvers that
    /// need both at one point: equal to [`Model::rhs`] then [`Model::jacobian`] (the default),
    /// a generated model computes the values they share once.
    fn rhs_and_jacobian(&self, p: &[f64], x: &[f64], t: f64, out: &mut [f64], sink: &mut JacSink) {
        self.rhs(p, x, t, out);
        self.jacobian(p, x, t, sink);
    }
    /// The values of [`Model::jacobian`]'s entries, written into `values` in the fixed order
    /// of [`Model::jacobian_pattern`] (entries at one position are to be summed). The default
    /// goes through triplets; a generated model writes the values alone (no indices).
    fn jacobian_values(&self, p: &[f64], x: &[f64], t: f64, values: &mut [f64]) {
        let trip = self.jacobian_triplets(p, x, t);
        values[..trip.len()]
            .iter_mut()
            .zip(&trip)
            .for_each(|(o, e)| *o = e.2);
    }
    /// [`Model::rhs`] and [`Model::jacobian_values`] in one call (a generated model shares
    /// their common values, as [`Model::rhs_and_jacobian`]).
    fn rhs_and_jacobian_values(
        &self,
        p: &[f64],
        x: &[f64],
        t: f64,
        out: &mut [f64],
        values: &mut [f64],
    ) {
        self.rhs(p, x, t, out);
        self.jacobian_values(p, x, t, values);
    }
    /// Where [`Model::jacobian`]'s entries go, in the order it gives them (a position may
    /// repeat; the order depends on the model and `n`, never on the state): the pattern of
    /// [`Model::jacobian_values`].
    fn jacobian_pattern(&self, p: &[f64]) -> Vec<(usize, usize)> {
        let mut x = vec![0.0; self.n_states()];
        self.equilibrium_guess(p, &mut x);
        let trip = self.jacobian_triplets(p, &x, 0.0);
        trip.into_iter().map(|(r, c, _)| (r, c)).collect()
    }
    /// The analytic parameter Jacobian `df/dp` (columns in parameter order).
    fn param_jacobian(&self, p: &[f64], x: &[f64], t: f64, sink: &mut JacSink);
    /// Pressure force on each body.
    fn pressure_forces(&self, p: &[f64], x: &[f64], out: &mut [f64]);
    /// Gradient of body `k`'s pressure force with respect to the states.
    fn pressure_force_gradient(&self, k: usize, p: &[f64], x: &[f64], out: &mut [f64]);
    /// The declared mass of every body, in body order: `out[k] = m_k`, so that an extra
    /// force `u` on body `k` enters the velocity row as `u / m_k`.
    fn body_masses(&self, p: &[f64], out: &mut [f64]);
    /// The equilibrium of docs/physics.md section 6 (exact for the declared charge at rest).
    fn equilibrium_guess(&self, p: &[f64], out: &mut [f64]);
    /// Pressure and volume of every vessel (CV elements, then spaces).
    fn pv(&self, p: &[f64], x: &[f64], pressure: &mut [f64], volume: &mut [f64]);
    /// Gas temperature of every CV element.
    fn temperatures(&self, p: &[f64], x: &[f64], out: &mut [f64]);
    /// Total gas mass in the CVs.
    fn gas_mass(&self, p: &[f64], x: &[f64]) -> f64;
    /// Stored energy `sum P V/(gamma-1) + sum m v^2/2 + k q^2/2 + sum C Tw` (walls).
    fn energy(&self, p: &[f64], x: &[f64]) -> f64;
    /// The terms of `dE/dt`.
    fn power(&self, p: &[f64], x: &[f64]) -> PowerTerms;
    /// The generated equations, as text or LaTeX.
    fn equations(&self, style: Style) -> String;
    /// The topology, for the bond-graph view.
    fn topology(&self) -> &'static crate::runtime::TopologyInfo;
    /// The measured channels declared with the model (`sensor` items), in declaration order;
    /// none by default.
    fn sensors(&self) -> &'static [SensorInfo] {
        &[]
    }
    /// The output of declared sensor `k` (index into [`Model::sensors`]) from the values `v`
    /// of the states it reads ([`SensorInfo::reads`]): writes its derivative in each read to
    /// `dv` and in each parameter it names to `dp` (the other entries untouched). The default
    /// is a state sensor's: the one value read. Generated for a model with expression sensors;
    /// [`crate::Observation`] resolves the reads at a model's `n` and closure.
    fn sensor_output(&self, k: usize, p: &[f64], v: &[f64], dv: &mut [f64], dp: &mut [f64]) -> f64 {
        let _ = (k, p, dp);
        dv[0] = 1.0;
        v[0]
    }
    /// The effects applied by `effect` items (at their null), in declaration order; none by
    /// default.
    fn effect_sites(&self) -> &'static [EffectSite] {
        &[]
    }
    /// The parameters a fit frees by default (`free a, b;`), in declaration order; none by
    /// default.
    fn declared_free(&self) -> &'static [&'static str] {
        &[]
    }

    /// Default parameter values.
    fn default_params(&self) -> Vec<f64> {
        self.params().iter().map(|p| p.default).collect()
    }
    /// Index of a parameter by name.
    fn param_index(&self, name: &str) -> Option<usize> {
        self.params().iter().position(|p| p.name == name)
    }
    /// The declared mass of body `k` (see [`Model::body_masses`]).
    fn body_mass(&self, k: usize, p: &[f64]) -> f64 {
        let mut m = vec![0.0; self.bodies().len()];
        self.body_masses(p, &mut m);
        m[k]
    }
    /// The state a declared sensor observes, at this model's `n` and closure: `None` when
    /// no sensor has that name, `Some(None)` when its state does not exist here (an array
    /// element beyond `n`, a mass state of the frozen closure) or the sensor is an expression
    /// (see [`crate::Observation`]).
    fn sensor_state(&self, name: &str) -> Option<Option<usize>> {
        let s = self.sensors().iter().find(|s| s.name == name)?;
        if s.state.is_empty() {
            return Some(None);
        }
        Some(self.states().iter().position(|st| st.name == s.state))
    }
    /// Names of the states.
    fn state_names(&self) -> Vec<String> {
        self.states().into_iter().map(|s| s.name).collect()
    }
    /// Dense column-major Jacobian.
    fn jacobian_dense(&self, p: &[f64], x: &[f64], t: f64) -> Vec<f64> {
        let n = self.n_states();
        let mut data = vec![0.0; n * n];
        self.jacobian(
            p,
            x,
            t,
            &mut JacSink::Dense {
                data: &mut data,
                nrows: n,
            },
        );
        data
    }
    /// Jacobian as coordinate triplets (entries at one position are to be summed).
    fn jacobian_triplets(&self, p: &[f64], x: &[f64], t: f64) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        self.jacobian(p, x, t, &mut JacSink::Triplets(&mut out));
        out
    }
    /// The structural sparsity pattern of the Jacobian: sorted, unique `(row, col)`.
    fn sparsity(&self, p: &[f64]) -> Vec<(usize, usize)> {
        let mut rc = self.jacobian_pattern(p);
        rc.sort_unstable();
        rc.dedup();
        rc
    }
    /// Dense column-major parameter Jacobian (`n_states` rows).
    fn param_jacobian_dense(&self, p: &[f64], x: &[f64], t: f64) -> Vec<f64> {
        let n = self.n_states();
        let mut data = vec![0.0; n * self.params().len()];
        self.param_jacobian(
            p,
            x,
            t,
            &mut JacSink::Dense {
                data: &mut data,
                nrows: n,
            },
        );
        data
    }
}
