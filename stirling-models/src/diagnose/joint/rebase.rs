//! The two stages at one point in a joint fit (records without `p_hot`): stage 1 reads the
//! pressure differences `P_i - P_cold` that the gas stage computes ([`crate::fit::unmeasured`]),
//! so when the joint fit moves the gas stage's variables, stage 1's prescribed pressures must
//! follow them.
//!
//! Why a fixed point and not more first-order links: the nominal calibration is a two-step
//! estimator (the gas stage from its own rows, then stage 1 with the gas stage's differences
//! given), and the joint fit of an effect is the same estimator with the effect added. An
//! effect the calibration absorbed moves the gas stage's parameters far when it is fitted
//! (a leak absorbed into the regenerator friction, `Rf` x0.045, returns `Rf` by a factor 20),
//! and stage 1 must then see the pressure drop of the fitted gas stage, not the nominal one,
//! or its damping keeps standing in for the drop it misses (`bd` x2). Re-evaluating the
//! differences at the fitted gas stage and fitting again until the gas stage stops moving
//! reaches that point exactly, for every variable of the gas stage (parameters, offsets,
//! sensor gains on the positions it reads), not only to first order in the few that a link
//! would carry; and it leaves the problem at the null, hence the score test and the verdicts
//! on clean records, as they were. Linking the gas parameters into stage 1 instead would make
//! stage 1's rows estimate them too (a different estimator than the calibration's, whose
//! optimum is no longer the null of the score test).
//!
//! Only where stage 1 sees how the variables it shares with the gas stage move the
//! differences: a model effect's strength is linked into stage 1 (its first-order derivative
//! is re-taken at each round), a pressure lag does not move them. A position gain does (the
//! gas stage reads the positions through it); it is estimated by the gas stage alone and
//! given to stage 1 at each rebase (`effect_vars::cut_gain`): a round then moves stage 1's
//! input and its gain together, as the two-step calibration would. (Informed by both stages
//! and unlinked, a round moved stage 1's input without its rows seeing why: on the
//! self-check's gain records that drove the gain away, closure 0.86 to -437.)

use super::memo::Memo;
use super::{is_mechanics, Joint};
use crate::fit::sensitivity::Signal;
use crate::fit::vars::{Sensor, VarKind};
use crate::fit::{unmeasured, FitError, FittedStage};

/// Where stage 1 of a joint problem reads the gas stage's pressure differences.
#[derive(Clone, Debug)]
pub struct DpLink {
    /// Joint stage indices of the mechanics stage and the gas stage.
    mech: usize,
    gas: usize,
    /// Per CV but the cold one (pressure order), the mechanics signal with its `P_i - P_cold`.
    base: Vec<usize>,
    /// Per linked variable of the mechanics stage: its index there and the index of the gas
    /// stage's variable with the same joint index.
    linked: Vec<(usize, usize)>,
    /// Per position gain the gas stage estimates: stage 1's given copy of it (index there,
    /// unit 0) and the gas stage's variable (`effect_vars::cut_gain`).
    cut: Vec<(usize, usize)>,
}

impl DpLink {
    /// The link of the joint stages `stages` (variables mapped by `map`), when stage 1 reads
    /// the differences of a gas stage that is part of the problem.
    pub fn of(stages: &[(usize, FittedStage)], map: &[Vec<usize>]) -> Option<DpLink> {
        let mech = stages
            .iter()
            .position(|(_, s)| is_mechanics(s) && !s.stage.derived.is_empty())?;
        let gas = stages.iter().position(|(_, s)| !is_mechanics(s))?;
        let ms = &stages[mech].1.stage;
        // the gains the gas stage reads positions through, and stage 1's given copy of each
        let mut cut = Vec::new();
        for (g, v) in stages[gas].1.stage.vars.iter().enumerate() {
            if !matches!(&v.kind, VarKind::Sensor(Sensor::Gain { given, .. }) if !given.is_empty())
            {
                continue;
            }
            let m = map[mech].iter().position(|&j| j == map[gas][g]);
            match m {
                Some(i) if ms.vars[i].scale == 0.0 => cut.push((i, g)),
                // a gain stage 1 would inform without seeing how it moves the differences
                Some(_) => return None,
                None => {}
            }
        }
        let base = ms
            .given
            .iter()
            .filter_map(|g| g.terms.iter().map(|t| t.0).find(|s| ms.derived.contains(s)))
            .collect();
        let linked = ms
            .vars
            .iter()
            .enumerate()
            .filter(|(_, v)| matches!(v.kind, VarKind::Linked { .. }))
            .filter_map(|(i, _)| {
                let g = map[gas].iter().position(|&j| j == map[mech][i])?;
                Some((i, g))
            })
            .collect();
        Some(DpLink {
            mech,
            gas,
            base,
            linked,
            cut,
        })
    }
}

impl Joint<'_> {
    /// Whether stage 1 reads the differences of a gas stage of the problem.
    pub fn has_dp_link(&self) -> bool {
        self.dp_link.is_some()
    }

    /// Stage 1's pressure differences, and the derivatives of its linked variables, taken
    /// from the gas stage at the joint variables `u` (the links then act from there).
    pub fn rebase(&mut self, u: &[f64]) -> Result<(), FitError> {
        self.rebase_memo(u, None)
    }

    /// [`Joint::rebase`], the run's signals taken from `memo` under the basis key `key` when
    /// it holds them (`u` must then be the basis's optimum with the candidate at its null:
    /// [`Joint::start`]), and kept there when computed.
    pub(super) fn rebase_memo(
        &mut self,
        u: &[f64],
        memo: Option<(&Memo, &str)>,
    ) -> Result<(), FitError> {
        let Some(link) = self.dp_link.clone() else {
            return Ok(());
        };
        let ug = self.stage_u(link.gas, u);
        let gas = &self.stages[link.gas].1;
        let values = gas.stage.values(&ug);
        let mech = &self.stages[link.mech].1.stage;
        let Some(last) = link.base.first().map(|&s| mech.signals[s].val.len() - 1) else {
            return Ok(());
        };
        let vars: Vec<usize> = link.linked.iter().map(|l| l.1).collect();
        let names: Vec<String> = link
            .linked
            .iter()
            .map(|l| mech.vars[l.0].name.clone())
            .collect();
        let run = || unmeasured::differences_at(&gas.stage, &ug, &vars, gas.first, last);
        let (dp, sens) = match memo {
            None => run()?,
            Some((memo, basis)) => {
                // the run's columns (every variable of the gas stage) set its steps: a key
                // of its own for each set, so a kept run is the one this joint would make
                let cols: Vec<&str> = gas.stage.vars.iter().map(|v| v.name.as_str()).collect();
                let key = &format!("{basis}|{}", cols.join(","));
                let got = recall(memo, key, &names);
                match got {
                    Some(hit) => hit,
                    None => {
                        let (dp, sens) = run()?;
                        keep(memo, key, &names, (&dp, &sens));
                        (dp, sens)
                    }
                }
            }
        };
        let mech = &mut self.stages[link.mech].1.stage;
        for (&s, d) in link.base.iter().zip(dp) {
            mech.signals[s] = d;
        }
        for &(mi, gi) in &link.cut {
            mech.vars[mi].initial = values[gi];
            let gain = mech.vars[mi].name.as_str();
            for &(_, j, travel) in self.held_travels.iter().filter(|h| h.0 == gain) {
                mech.p[j] = travel / (1.0 + values[gi]);
            }
        }
        for (&(mi, gi), d) in link.linked.iter().zip(sens) {
            let cut = mech.vars[mi].scale == 0.0;
            if let VarKind::Linked { pairs, at } = &mut mech.vars[mi].kind {
                for (&(_, s), sig) in pairs.iter().zip(d) {
                    mech.signals[s] = sig;
                }
                *at = values[gi];
            }
            if cut {
                // a cut link: its value is where the differences were taken
                mech.vars[mi].initial = values[gi];
            }
        }
        Ok(())
    }

    /// The largest change of the gas stage's free variables from `a` to `b`, in standard
    /// errors at `b` (`jacobian`: the weighted joint Jacobian there, whose residuals have unit
    /// variance; `fixed`: held variables). Infinite when the covariance cannot be formed.
    pub fn gas_change(
        &self,
        a: &[f64],
        b: &[f64],
        jacobian: &nalgebra::DMatrix<f64>,
        fixed: &[usize],
    ) -> f64 {
        let Some(link) = &self.dp_link else {
            return 0.0;
        };
        let free: Vec<usize> = (0..jacobian.ncols())
            .filter(|c| !fixed.contains(c))
            .collect();
        let Some(var) = crate::diagnose::covariance::covariance_diagonal(jacobian, &free) else {
            return f64::INFINITY;
        };
        self.map[link.gas]
            .iter()
            .filter_map(|&j| free.iter().position(|&c| c == j).map(|k| (j, var[k])))
            .map(|(j, v)| (a[j] - b[j]).abs() / v.sqrt().max(1e-300))
            .fold(0.0, f64::max)
    }
}

/// The held end-stop travels among `shapes` (`xmax`, `ymax`: travels seen in the measured
/// acceleration, less the position offset, in the sensor's units) with the gain that scales
/// each and its model parameter. Why: the gain is the sensor's (`x_meas = (1 + gain_x) x`),
/// the stops are the model's, so a travel read off the record is `(1 + gain)` times the
/// model's; held as read beside a fitted gain, the stops let the model body run that much too
/// far and the gain made the held-out fit worse where it was right (the self-check's
/// `end_stops + sensor_gain` records: `gain_y` 4.9 % on a 5 % truth, held-out BIC +3986).
pub(super) fn held_travels(
    model: &dyn stirling_dsl::Model,
    shapes: &[(&str, f64)],
) -> Vec<(&'static str, usize, f64)> {
    shapes
        .iter()
        .filter_map(|&(name, v)| {
            let gain = match name {
                "xmax" => "gain_x",
                "ymax" => "gain_y",
                _ => return None,
            };
            Some((gain, model.param_index(name)?, v))
        })
        .collect()
}

/// The memo's name of the differences (no parameter's name holds a `#`).
const DIFFERENCES: &str = "#differences";

/// The memo's differences and linked derivatives at the basis `key`, when it holds all of
/// them.
fn recall(memo: &Memo, key: &str, names: &[String]) -> Option<(Vec<Signal>, Vec<Vec<Signal>>)> {
    let dp = memo.rebased(key, DIFFERENCES)?;
    let sens = names
        .iter()
        .map(|n| memo.rebased(key, n))
        .collect::<Option<Vec<_>>>()?;
    Some((dp, sens))
}

/// Keep the differences and linked derivatives of a rebase at the basis `key`.
fn keep(memo: &Memo, key: &str, names: &[String], (dp, sens): (&[Signal], &[Vec<Signal>])) {
    memo.keep_rebased(key, DIFFERENCES, dp);
    for (n, d) in names.iter().zip(sens) {
        memo.keep_rebased(key, n, d);
    }
}
