//! The nonphysical-state check run after every accepted step: non-finite entries,
//! non-positive volume (of every vessel with a positive rest volume), pressure,
//! temperature or mass stop the run with an error naming the time and the quantity.
//!
//! Everything that does not change along a run (rest volumes, which states are
//! masses, buffer sizes) is computed once; names are formatted only for an error.

use std::cell::RefCell;

use stirling_dsl::{Model, StateKind};

use super::SimError;

/// A reusable checker for one model and parameter set.
pub struct PhysicalCheck<'m> {
    model: &'m dyn Model,
    p: &'m [f64],
    rest: Vec<f64>,
    masses: Vec<usize>,
    n_cv: usize,
    /// Whether the temperatures need their own check: not when every CV's mass is a state,
    /// for then `T = P V / (m R)` (docs/physics.md) is positive once the pressure, volume and
    /// mass checked before it are (the temperatures cost a pass over every vessel's terms,
    /// 3.5 % of a simulated second at n = 100).
    temperatures: bool,
    buffers: RefCell<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

impl<'m> PhysicalCheck<'m> {
    /// Precompute what the check needs.
    pub fn new(model: &'m dyn Model, p: &'m [f64]) -> Self {
        let nv = model.vessel_names().len();
        let mut eq = vec![0.0; model.n_states()];
        model.equilibrium_guess(p, &mut eq);
        let (mut pr, mut rest) = (vec![0.0; nv], vec![0.0; nv]);
        model.pv(p, &eq, &mut pr, &mut rest);
        let states = model.states();
        let masses: Vec<usize> = (0..states.len())
            .filter(|&i| matches!(states[i].kind, StateKind::Mass(_)))
            .collect();
        let n_cv = states
            .iter()
            .filter(|s| matches!(s.kind, StateKind::Pressure(_)))
            .count();
        let buffers = RefCell::new((vec![0.0; nv], vec![0.0; nv], vec![0.0; n_cv]));
        let temperatures = n_cv > 0 && masses.len() != n_cv;
        Self {
            model,
            p,
            rest,
            masses,
            n_cv,
            temperatures,
            buffers,
        }
    }

    /// `Ok` if `x` is physical at time `t`.
    pub fn check(&self, t: f64, x: &[f64]) -> Result<(), SimError> {
        let bad = |quantity: String, value: f64| Err(SimError::Nonphysical { t, quantity, value });
        if let Some(i) = x.iter().position(|v| !v.is_finite()) {
            return bad(format!("state `{}`", self.model.state_names()[i]), x[i]);
        }
        let mut guard = self.buffers.borrow_mut();
        let (pr, vol, temp) = &mut *guard;
        self.model.pv(self.p, x, pr, vol);
        for i in 0..pr.len() {
            // a space declared without a rest volume (the bounce space) only counts
            // displacement; a CV element (the first `n_cv` vessels) always holds gas
            if (i < self.n_cv || self.rest[i] > 0.0) && !(vol[i] > 0.0) {
                return bad(format!("volume of `{}` (m^3)", self.vessel(i)), vol[i]);
            }
            if !(pr[i] > 0.0) {
                return bad(format!("pressure of `{}` (Pa)", self.vessel(i)), pr[i]);
            }
        }
        if let Some(&i) = self.masses.iter().find(|&&i| !(x[i] > 0.0)) {
            return bad(
                format!("gas mass `{}` (kg)", self.model.state_names()[i]),
                x[i],
            );
        }
        if !self.temperatures {
            return Ok(());
        }
        self.model.temperatures(self.p, x, temp);
        if let Some(i) = temp.iter().position(|v| !(*v > 0.0)) {
            return bad(format!("temperature of `{}` (K)", self.vessel(i)), temp[i]);
        }
        Ok(())
    }

    fn vessel(&self, i: usize) -> String {
        self.model
            .vessel_names()
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("vessel {i}"))
    }
}

/// One-off check (builds a [`PhysicalCheck`]; in a loop, build it once instead).
pub fn check_physical(model: &dyn Model, p: &[f64], t: f64, x: &[f64]) -> Result<(), SimError> {
    PhysicalCheck::new(model, p).check(t, x)
}
