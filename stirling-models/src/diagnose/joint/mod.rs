//! The joint problem of one candidate effect: the calibrated driven subsystems (the two
//! stages of [`crate::fit`]) that the effect touches, each extended by the effect's variables,
//! stacked into one least-squares problem whose variables are every stage's own variables
//! plus the shared effect strengths.
//!
//! - Model effects (leak, Coulomb friction, end stops, quadratic regenerator friction) are
//!   parameters of the augmented model: a variable of the stage whose rows they enter, with
//!   forward sensitivities like any parameter.
//! - Sensor effects act on both stages: a pressure-transducer lag un-lags stage 1's pressure input
//!   and lags stage 2's pressure output; a position gain rescales stage 1's position outputs and
//!   stage 2's prescribed positions ([`Sensor`](crate::fit::vars::Sensor)).
//!
//! At the null of the strengths the problem is the nominal calibration, so its Jacobian there gives
//! the score test ([`crate::diagnose::score`]) and Levenberg-Marquardt from there the joint fit.

use nalgebra::DMatrix;
use stirling_dsl::Model;

/// The variables an effect adds, and where they enter.
mod effect_vars;
/// What building a joint problem computes again and again, computed once.
mod memo;
/// Stage 1's pressure differences re-evaluated at the fitted gas stage.
mod rebase;

use super::DiagnoseError;
use crate::effects::EffectInfo;
use crate::fit::prior::prior_rows;
use crate::fit::vars::VarKind;
use crate::fit::{FitError, FittedStage};
use effect_vars::EffectVars;

/// One effect variable of the joint problem.
#[derive(Clone, Debug)]
pub struct EffectVar {
    pub name: String,
    /// Index among the joint variables.
    pub index: usize,
    /// Value at the null, and the unit of the scaled variable.
    pub null: f64,
    pub scale: f64,
    /// Must stay on the positive side of its null.
    pub bounded: bool,
    /// A shape parameter (end-stop travel): not a strength; not tested, only fitted.
    pub shape: bool,
    /// A variable of an effect accepted at an earlier step ([`Basis`]): fitted with the
    /// nominal variables, never tested.
    pub base: bool,
    pub unit: String,
    /// The range the model declares for it (`in lo..hi`): the joint fit starts and stays
    /// inside.
    pub range: Option<(f64, f64)>,
}

impl EffectVar {
    /// The scaled start `u` moved inside the declared range (a hundredth of it away from
    /// the ends).
    pub fn inside(&self, u: f64) -> f64 {
        let Some((lo, hi)) = self.range else {
            return u;
        };
        let margin = 0.01 * (hi - lo);
        let v = (self.null + self.scale * u).clamp(lo + margin, hi - margin);
        (v - self.null) / self.scale
    }
}

/// An effect with the shape setting (end-stop travels) it is fitted from: a candidate, or
/// one accepted at an earlier step of the diagnosis.
#[derive(Clone, Debug)]
pub struct EffectAt {
    pub effect: &'static EffectInfo,
    pub shapes: Vec<(&'static str, f64)>,
}

/// What a candidate extends: the nominal stages with the effects accepted so far, at their
/// joint optimum `x` (every nominal stage's variables, then the accepted effects' variables).
#[derive(Clone, Debug)]
pub struct Basis {
    pub effects: Vec<EffectAt>,
    pub x: Vec<f64>,
    /// The runs every joint problem on this calibration shares (`joint/memo.rs`).
    pub memo: memo::Memo,
    /// The accepted effects' shapes stay where they were set (end-stop travels seen in the
    /// measured acceleration, [`crate::diagnose::stops_equation`]) instead of being refitted.
    pub held_shapes: bool,
}

impl Basis {
    /// The nominal calibration: no effect accepted.
    pub fn nominal(nominal: &[FittedStage]) -> Self {
        Basis {
            effects: Vec::new(),
            x: nominal.iter().flat_map(|s| s.u.iter().copied()).collect(),
            memo: memo::Memo::default(),
            held_shapes: false,
        }
    }
}

/// The stacked problem.
#[derive(Clone)]
pub struct Joint<'a> {
    /// The stages the effect touches (index into the nominal stages, extended stage).
    pub stages: Vec<(usize, FittedStage<'a>)>,
    /// Per stage: the joint index of each of its variables.
    pub map: Vec<Vec<usize>>,
    /// Per stage: the residual weight `1 / s` (`s^2`: the nominal fit's variance factor).
    pub weight: Vec<f64>,
    pub n_vars: usize,
    pub effect: Vec<EffectVar>,
    /// Where stage 1 reads the gas stage's pressure differences, when both are in the
    /// problem (records without `p_hot`; see [`Joint::rebase`]).
    dp_link: Option<rebase::DpLink>,
    /// The basis's optimum: the start of the candidate's variables at their null.
    base_x: Vec<f64>,
    /// Held end-stop travels (`Basis::held_shapes`) as seen in the record: the position
    /// gain's name that scales each, the model parameter and the travel ([`Joint::rebase`]
    /// divides it by the gain).
    held_travels: Vec<(&'static str, usize, f64)>,
}

/// Whether a stage is the mechanics stage (positions out, pressures in).
fn is_mechanics(st: &FittedStage) -> bool {
    st.stage.outputs.iter().any(|o| o.channel == "x")
}

/// The nominal variance factor of a stage: `|r|^2 / (N - k)` at its optimum.
pub fn variance_factor(st: &FittedStage) -> Result<f64, FitError> {
    let (mut r, _) = st.stage.residuals(&st.u, st.first, st.last, &st.keep)?;
    r.truncate(st.keep.len() * st.stage.outputs.len());
    let dof = r
        .len()
        .saturating_sub(st.stage.vars.len() + st.stage.drift * st.stage.outputs.len())
        .max(1);
    Ok(r.iter().map(|v| v * v).sum::<f64>() / dof as f64)
}

impl<'a> Joint<'a> {
    /// Extend the nominal stages by the variables of the accepted effects of `basis` and of
    /// the candidates `cands` (one effect, or a pair tried together; `free_shapes`: fit their
    /// shape parameters too). `s2`: the nominal variance factors. With accepted effects, stage 1's pressure
    /// differences are taken at the basis's optimum ([`Joint::rebase`]).
    pub fn new(
        model: &dyn Model,
        nominal: &[FittedStage<'a>],
        s2: &[f64],
        basis: &Basis,
        cands: &[EffectAt],
        free_shapes: bool,
    ) -> Result<Self, DiagnoseError> {
        let vars = EffectVars::of(
            model,
            (nominal, &basis.memo),
            (&basis.effects, basis.held_shapes),
            cands,
            free_shapes,
        )?;
        let all_shapes: Vec<(&str, f64)> = basis
            .effects
            .iter()
            .chain(cands)
            .flat_map(|a| a.shapes.iter().copied())
            .collect();
        let n_nom: usize = nominal.iter().map(|s| s.stage.vars.len()).sum();
        let (mut stages, mut map, mut weight) = (Vec::new(), Vec::new(), Vec::new());
        for (si, st) in nominal.iter().enumerate() {
            let Some((ext, m)) = vars.extend(model, nominal, si, st, &all_shapes) else {
                continue;
            };
            map.push(m);
            weight.push(1.0 / s2[si].max(1e-12).sqrt());
            stages.push((si, ext));
        }
        let dp_link = rebase::DpLink::of(&stages, &map);
        let held_travels = if basis.held_shapes {
            rebase::held_travels(model, &all_shapes)
        } else {
            Vec::new()
        };
        let mut joint = Joint {
            stages,
            map,
            weight,
            n_vars: n_nom + vars.effect.len(),
            effect: vars.effect,
            dp_link,
            base_x: basis.x.clone(),
            held_travels,
        };
        if !basis.effects.is_empty() {
            let key = memo::basis_key(&basis.x, &basis.effects);
            joint.rebase_memo(&joint.start(), Some((&basis.memo, &key)))?;
        }
        Ok(joint)
    }

    /// The joint variables at the basis's optimum (the nominal one, or the last step's), the
    /// candidate at its null.
    pub fn start(&self) -> Vec<f64> {
        let mut u = self.base_x.clone();
        u.resize(self.n_vars, 0.0);
        u
    }

    /// The candidates' variables (those of no accepted effect).
    pub fn candidate(&self) -> impl Iterator<Item = &EffectVar> {
        self.effect.iter().filter(|v| !v.base)
    }

    /// [`Joint::start`] with the nominal model parameters back at their starting values (the
    /// engineering estimates): a start in the effect's own basin when the nominal calibration
    /// absorbed the effect into parameters that moved far (a leak into the heat transfer).
    pub fn reset_start(&self) -> Vec<f64> {
        let mut u = self.start();
        let n_nom = self.n_vars - self.effect.len();
        for (k, (_, st)) in self.stages.iter().enumerate() {
            for (v, &i) in st.stage.vars.iter().zip(&self.map[k]) {
                if i < n_nom && matches!(v.kind, VarKind::Param(_)) {
                    u[i] = 0.0;
                }
            }
        }
        u
    }

    /// The prior cost (sum of squared prior residuals, [`crate::fit::prior`]) of the nominal
    /// parameters at the joint variables `u`.
    pub fn prior_cost(&self, u: &[f64]) -> f64 {
        (0..self.stages.len())
            .flat_map(|k| prior_rows(&self.stages[k].1.stage.vars, &self.stage_u(k, u)))
            .map(|row| row.r * row.r)
            .sum()
    }

    /// A stage's variables from the joint ones.
    pub fn stage_u(&self, k: usize, u: &[f64]) -> Vec<f64> {
        self.map[k].iter().map(|&i| u[i]).collect()
    }

    /// Weighted stacked residuals and Jacobian, with the row ranges of every output block
    /// (residuals of one output of one stage, in time order) and of every prior row (a block
    /// of one row; the priors are standardized already and keep weight 1).
    pub fn residuals(
        &self,
        u: &[f64],
    ) -> Result<(Vec<f64>, DMatrix<f64>, Vec<(usize, usize)>), FitError> {
        use rayon::prelude::*;
        // the stages are independent runs: in parallel
        let parts = (0..self.stages.len())
            .into_par_iter()
            .map(|k| {
                let st = &self.stages[k].1;
                st.stage
                    .residuals(&self.stage_u(k, u), st.first, st.last, &st.keep)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let rows: usize = parts.iter().map(|(r, _)| r.len()).sum();
        let mut r = Vec::with_capacity(rows);
        let mut jm = DMatrix::zeros(rows, self.n_vars);
        let mut blocks = Vec::new();
        for (k, (rk, jk)) in parts.iter().enumerate() {
            let per = self.stages[k].1.keep.len();
            let n_out = self.stages[k].1.stage.outputs.len();
            let row0 = r.len();
            let w = |i: usize| if i < n_out * per { self.weight[k] } else { 1.0 };
            r.extend(rk.iter().enumerate().map(|(i, v)| v * w(i)));
            for (c, &jc) in self.map[k].iter().enumerate() {
                for i in 0..rk.len() {
                    jm[(row0 + i, jc)] += w(i) * jk[(i, c)];
                }
            }
            for o in 0..n_out {
                blocks.push((row0 + o * per, row0 + (o + 1) * per));
            }
            blocks.extend((row0 + n_out * per..row0 + rk.len()).map(|i| (i, i + 1)));
        }
        Ok((r, jm, blocks))
    }

    /// The weighted stacked residuals of [`Joint::residuals`] without the Jacobian (a
    /// Levenberg-Marquardt trial point, [`crate::fit::lm::minimize_split`]).
    pub fn trial_residuals(&self, u: &[f64]) -> Result<Vec<f64>, FitError> {
        use rayon::prelude::*;
        let parts = (0..self.stages.len())
            .into_par_iter()
            .map(|k| {
                let st = &self.stages[k].1;
                st.stage
                    .trial_residuals(&self.stage_u(k, u), st.first, st.last, &st.keep)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut r = Vec::new();
        for (k, rk) in parts.iter().enumerate() {
            let st = &self.stages[k].1;
            let n = st.keep.len() * st.stage.outputs.len();
            let w = self.weight[k];
            r.extend(
                rk.iter()
                    .enumerate()
                    .map(|(i, v)| if i < n { v * w } else { *v }),
            );
        }
        Ok(r)
    }

    /// Stacked, weighted input-noise draws of the joint stages (`per_stage[s][k]`: draw `k`
    /// of nominal stage `s`; see [`crate::fit::driven::Stage::input_noise_draws`]).
    pub fn noise_draws(&self, per_stage: &[Vec<Vec<f64>>]) -> Vec<Vec<f64>> {
        let k = self
            .stages
            .iter()
            .map(|(s, _)| per_stage.get(*s).map_or(0, |d| d.len()))
            .min()
            .unwrap_or(0);
        (0..k)
            .map(|d| {
                self.stages
                    .iter()
                    .zip(&self.weight)
                    .flat_map(|((s, _), w)| per_stage[*s][d].iter().map(move |v| v * w))
                    .collect()
            })
            .collect()
    }

    /// Effect values from the joint variables.
    pub fn effect_values(&self, u: &[f64]) -> Vec<f64> {
        self.effect
            .iter()
            .map(|e| e.null + e.scale * u[e.index])
            .collect()
    }
}
