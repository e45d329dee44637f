//! Cycle work: `W_i = closed-integral P_i dV_i = integral_0^T P_i dV_i/dt dt` for every
//! vessel, total `W = sum W_i`, indicated power `W f`. Positive work is done by the gas.
//!
//! The integrand is periodic and smooth, so the trapezoid rule on uniform samples
//! converges spectrally. `dV_i/dt` is exact: volumes are affine in the positions, so
//! `dV/dt = (V(x + h f(x)) - V(x)) / h` for any `h`.

use stirling_dsl::Model;

/// Work per vessel and in total over one cycle.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleWork {
    /// Vessel names (as [`Model::vessel_names`]).
    pub vessels: Vec<String>,
    /// `closed-integral P dV` per vessel (J).
    pub per_vessel: Vec<f64>,
    /// Sum over the vessels (J).
    pub total: f64,
}

/// Work over one period from uniform samples whose last equals the first.
pub fn cycle_work(model: &dyn Model, p: &[f64], period: f64, states: &[Vec<f64>]) -> CycleWork {
    let vessels = model.vessel_names();
    let nv = vessels.len();
    let n = states.len().saturating_sub(1).max(1);
    let dt = period / n as f64;
    let mut per_vessel = vec![0.0; nv];
    let (mut pr, mut v, mut pr2, mut v2) =
        (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
    let mut f = vec![0.0; model.n_states()];
    for x in states.iter().take(n) {
        model.pv(p, x, &mut pr, &mut v);
        model.rhs(p, x, 0.0, &mut f);
        let h = 1e-6;
        let xh: Vec<f64> = x.iter().zip(&f).map(|(a, b)| a + h * b).collect();
        model.pv(p, &xh, &mut pr2, &mut v2);
        for i in 0..nv {
            per_vessel[i] += pr[i] * (v2[i] - v[i]) / h * dt;
        }
    }
    let total = per_vessel.iter().sum();
    CycleWork {
        vessels,
        per_vessel,
        total,
    }
}

/// Indicated power (W) of a cycle of work `w` (J) at `frequency_hz`.
pub fn indicated_power(w: f64, frequency_hz: f64) -> f64 {
    w * frequency_hz
}

/// One `(V, P)` loop per vessel (in [`Model::vessel_names`] order) along sampled states.
pub fn pv_loops(model: &dyn Model, p: &[f64], states: &[Vec<f64>]) -> Vec<Vec<(f64, f64)>> {
    let nv = model.vessel_names().len();
    let mut loops = vec![Vec::with_capacity(states.len()); nv];
    let (mut pr, mut v) = (vec![0.0; nv], vec![0.0; nv]);
    for x in states {
        model.pv(p, x, &mut pr, &mut v);
        for i in 0..nv {
            loops[i].push((v[i], pr[i]));
        }
    }
    loops
}
