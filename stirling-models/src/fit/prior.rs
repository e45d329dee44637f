//! Log-normal priors on fitted model parameters: the starting values are engineering
//! estimates, and a calibration that fits only because a parameter moved far from its
//! estimate (a heat-transfer coefficient by a factor of four) is itself a symptom of an
//! omitted effect. With a prior of log standard deviation `s` on a parameter that starts at
//! `θ0`, the residual `ln(θ / θ0) / s` joins the least-squares problem (a maximum a posteriori
//! fit). Below `θ / θ0 = FLOOR` the logarithm continues linearly, so a trial step through
//! zero stays finite.

use super::vars::Var;

/// Ratio below which the log residual continues linearly.
const FLOOR: f64 = 0.05;

/// One prior residual: the variable it belongs to, its value and its derivative with
/// respect to the scaled variable.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PriorRow {
    pub var: usize,
    pub r: f64,
    pub dr_du: f64,
}

/// The prior residuals of `vars` at the scaled values `u` (in variable order).
pub fn prior_rows(vars: &[Var], u: &[f64]) -> Vec<PriorRow> {
    vars.iter()
        .zip(u)
        .enumerate()
        .filter_map(|(k, (v, &uk))| {
            let s = v.prior.filter(|s| *s > 0.0 && v.initial != 0.0)?;
            let ratio = 1.0 + v.scale * uk / v.initial;
            let dratio = v.scale / v.initial;
            let (r, dr) = if ratio >= FLOOR {
                (ratio.ln(), dratio / ratio)
            } else {
                (FLOOR.ln() + (ratio - FLOOR) / FLOOR, dratio / FLOOR)
            };
            Some(PriorRow {
                var: k,
                r: r / s,
                dr_du: dr / s,
            })
        })
        .collect()
}

/// How many prior residuals `vars` carry.
pub fn prior_count(vars: &[Var]) -> usize {
    vars.iter()
        .filter(|v| v.prior.is_some_and(|s| s > 0.0) && v.initial != 0.0)
        .count()
}
