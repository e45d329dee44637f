//! The joint problem of one candidate effect: the calibrated driven subsystems (the two
//! stages of [`crate::fit`]) that the effect touches, each extended by the effect's variables,
//! stacked into one least-squares problem whose variables are every stage's own variables
//! plus the shared effect strengths.
//!
//! - Model effects (leak, Coulomb friction, end stops, quadratic regenerator friction) are
//!   parameters of the augmented model: a variable of the stage whose rows they enter, with
//!   forward sensitivities like any parameter.
//! - Sensor effects act on both stages: a pressure-transducer lag un-lags stage 1's pressure
//!   input and lags stage 2's pressure output; a position gain rescales stage 1's position
//!   outputs and stage 2's prescribed positions ([`crate::fit::driven::Sensor`]).
//!
//! At the null of the strengths the problem is the nominal calibration, so its Jacobian there
//! gives the score test ([`super::score`]) and Levenberg-Marquardt from there the joint fit.

use nalgebra::DMatrix;
use stirling_dsl::Model;

use super::DiagnoseError;
use crate::effects::{EffectInfo, EffectTarget};
use crate::fit::prior::prior_rows;
use crate::fit::sensitivity::Signal;
use crate::fit::vars::{Sensor, Var, VarKind};
use crate::fit::{classify, unmeasured, FitError, FittedStage};

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
    pub unit: String,
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
    /// Extend the nominal stages by the variables of `e` (`shapes`: values of the effect's
    /// shape parameters; `free_shapes`: fit them too). `s2`: the nominal variance factors.
    pub fn new(
        model: &dyn Model,
        nominal: &[FittedStage<'a>],
        s2: &[f64],
        e: &EffectInfo,
        shapes: &[(&str, f64)],
        free_shapes: bool,
    ) -> Result<Self, DiagnoseError> {
        let mut stages: Vec<(usize, FittedStage<'a>)> = Vec::new();
        let mut effect: Vec<EffectVar> = Vec::new();
        let n_nom: usize = nominal.iter().map(|s| s.stage.vars.len()).sum();
        // which stages each effect variable goes to, with its variable kind there
        let mut adds: Vec<(usize, Var)> = Vec::new();
        // signals the linked variables of the mechanics stage read (see [`link`])
        let mut linked: Vec<(usize, Vec<Signal>)> = Vec::new();
        for q in e.params {
            let shape_value = shapes.iter().find(|(n, _)| *n == q.name).map(|s| s.1);
            if q.null.is_none() && !(free_shapes && shape_value.is_some()) {
                continue;
            }
            let (initial, scale) = match (q.null, shape_value) {
                (Some(null), _) => (null, q.typical),
                (None, Some(v)) => (v, 0.1 * v.abs().max(1e-9)),
                (None, None) => unreachable!("filtered above"),
            };
            let index = n_nom + effect.len();
            let bounded = q.null.is_some() && !q.name.starts_with("gain");
            effect.push(EffectVar {
                name: q.name.into(),
                index,
                null: initial,
                scale,
                bounded,
                shape: q.null.is_none(),
                unit: q.unit.into(),
            });
            for (si, st) in nominal.iter().enumerate() {
                if let Some(kind) = kind_in(model, st, e, q.name)? {
                    adds.push((
                        si,
                        Var {
                            name: q.name.into(),
                            initial,
                            scale,
                            kind,
                            prior: None,
                        },
                    ));
                }
            }
            if let Some((si, var, sigs)) = link(nominal, &adds, &linked, q.name)? {
                adds.push((si, var));
                linked.push((si, sigs));
            }
            if !adds.iter().any(|(_, v)| v.name == q.name) {
                return Err(DiagnoseError::NotDriven {
                    param: q.name.into(),
                    model: model.name().into(),
                });
            }
        }
        let mut map = Vec::new();
        let mut weight = Vec::new();
        for (si, st) in nominal.iter().enumerate() {
            let extra: Vec<&(usize, Var)> = adds.iter().filter(|(s, _)| *s == si).collect();
            if extra.is_empty() {
                continue;
            }
            let mut ext = st.clone();
            for (_, sigs) in linked.iter().filter(|(s, _)| *s == si) {
                let n0 = ext.stage.signals.len();
                ext.stage.signals.extend(sigs.iter().cloned());
                ext.stage.derived.extend(n0..ext.stage.signals.len());
            }
            for (name, v) in shapes {
                if let Some(j) = model.param_index(name) {
                    ext.stage.p[j] = *v;
                }
            }
            let offset: usize = nominal[..si].iter().map(|s| s.stage.vars.len()).sum();
            let mut m: Vec<usize> = (offset..offset + st.stage.vars.len()).collect();
            for (_, v) in extra {
                let k = effect
                    .iter()
                    .find(|ev| ev.name == v.name)
                    .expect("pushed above")
                    .index;
                m.push(k);
                ext.stage.vars.push(v.clone());
                ext.u.push(0.0);
            }
            map.push(m);
            weight.push(1.0 / s2[si].max(1e-12).sqrt());
            stages.push((si, ext));
        }
        Ok(Joint {
            stages,
            map,
            weight,
            n_vars: n_nom + effect.len(),
            effect,
        })
    }

    /// The joint variables at the nominal optimum with the effect at its null.
    pub fn start(&self, nominal: &[FittedStage]) -> Vec<f64> {
        let mut u: Vec<f64> = nominal.iter().flat_map(|s| s.u.iter().copied()).collect();
        u.resize(self.n_vars, 0.0);
        u
    }

    /// [`Joint::start`] with the nominal model parameters back at their starting values (the
    /// engineering estimates): a start in the effect's own basin when the nominal calibration
    /// absorbed the effect into parameters that moved far (a leak into the heat transfer).
    pub fn reset_start(&self, nominal: &[FittedStage]) -> Vec<f64> {
        let mut u = self.start(nominal);
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
        let mut parts = Vec::new();
        for (k, (_, st)) in self.stages.iter().enumerate() {
            let (r, j) = st
                .stage
                .residuals(&self.stage_u(k, u), st.first, st.last, &st.keep)?;
            parts.push((r, j));
        }
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

/// On records without `p_hot` the mechanics stage reads the gas stage's pressure differences
/// ([`crate::fit::unmeasured`]); a gas-stage effect (quadratic regenerator friction, a leak)
/// changes them, so the mechanics stage gets the effect too, linked to first order: its
/// prescribed pressures move by `(value - null) dP/dvalue`, the derivative from the gas
/// stage's forward sensitivities at the nominal optimum. Returns the mechanics stage, its
/// variable and the derivative signals (appended after those already queued in `linked`).
fn link(
    nominal: &[FittedStage],
    adds: &[(usize, Var)],
    linked: &[(usize, Vec<Signal>)],
    name: &str,
) -> Result<Option<(usize, Var, Vec<Signal>)>, DiagnoseError> {
    let Some(mech) = nominal
        .iter()
        .position(|s| is_mechanics(s) && !s.stage.derived.is_empty())
    else {
        return Ok(None);
    };
    if adds.iter().any(|(s, v)| *s == mech && v.name == name) {
        return Ok(None);
    }
    let Some((gi, gvar)) = adds
        .iter()
        .find(|(s, v)| *s != mech && v.name == name && matches!(v.kind, VarKind::Param(_)))
    else {
        return Ok(None);
    };
    let gas = &nominal[*gi];
    let mut st = gas.stage.clone();
    st.vars.push(gvar.clone());
    let mut u = gas.u.clone();
    u.push(0.0);
    let d = unmeasured::difference_sensitivity(&st, &u, st.vars.len() - 1, gas.first)?;
    let cold = d.len() - 1;
    let queued: usize = linked
        .iter()
        .filter(|(s, _)| *s == mech)
        .map(|(_, v)| v.len())
        .sum();
    let base = nominal[mech].stage.signals.len() + queued;
    let var = Var {
        kind: VarKind::Linked((0..cold).map(|i| (i, base + i)).collect()),
        prior: None,
        ..gvar.clone()
    };
    Ok(Some((mech, var, d.into_iter().take(cold).collect())))
}

/// The kind of an effect variable in a stage, if it enters it.
fn kind_in(
    model: &dyn Model,
    st: &FittedStage,
    e: &EffectInfo,
    name: &str,
) -> Result<Option<VarKind>, DiagnoseError> {
    let mech = is_mechanics(st);
    let outputs = |pred: &dyn Fn(&str) -> bool| -> Vec<usize> {
        st.stage
            .outputs
            .iter()
            .enumerate()
            .filter(|(_, o)| pred(&o.channel))
            .map(|(i, _)| i)
            .collect()
    };
    Ok(match (e.target, name) {
        (EffectTarget::Model, _) => {
            let j = model
                .param_index(name)
                .ok_or_else(|| DiagnoseError::UnknownParameter {
                    name: name.into(),
                    model: model.name().into(),
                })?;
            // which rows the effect enters, with its strengths on and its shapes (travel,
            // smoothing) small, so that it acts at the probe state `classify` uses
            let mut p = st.stage.p.clone();
            for q in e.params {
                if let Some(i) = model.param_index(q.name) {
                    p[i] = if q.null.is_some() {
                        q.typical
                    } else {
                        1e-4 * q.typical
                    };
                }
            }
            let shape = e.params.iter().any(|q| q.name == name && q.null.is_none());
            let probe: Vec<String> = if shape {
                e.params
                    .iter()
                    .filter(|q| q.null.is_some())
                    .map(|q| q.name.to_string())
                    .collect()
            } else {
                vec![name.to_string()]
            };
            let enters = probe.iter().any(|q| {
                classify(model, &p, std::slice::from_ref(q)).is_ok_and(|(m, g)| {
                    if mech {
                        !m.is_empty()
                    } else {
                        !g.is_empty()
                    }
                })
            });
            enters.then_some(VarKind::Param(j))
        }
        (EffectTarget::Sensor, "tau_p") => Some(if mech {
            VarKind::Sensor(Sensor::Lag {
                // the measured pressures only, not the model's pressure differences
                signals: (0..st.stage.signals.len())
                    .filter(|s| !st.stage.derived.contains(s))
                    .collect(),
                outputs: vec![],
            })
        } else {
            VarKind::Sensor(Sensor::Lag {
                signals: vec![],
                outputs: outputs(&|c| c.starts_with('p')),
            })
        }),
        (EffectTarget::Sensor, "gain_x" | "gain_y") => {
            let ch = &name[5..];
            Some(if mech {
                VarKind::Sensor(Sensor::Gain {
                    given: vec![],
                    outputs: outputs(&|c| c == ch),
                })
            } else {
                // stage 2 reads the positions as signals 0 (x) and 1 (y)
                let sig = usize::from(ch == "y");
                let given = st
                    .stage
                    .given
                    .iter()
                    .enumerate()
                    .filter(|(_, g)| g.terms.iter().any(|t| t.0 == sig))
                    .map(|(i, _)| i)
                    .collect();
                VarKind::Sensor(Sensor::Gain {
                    given,
                    outputs: vec![],
                })
            })
        }
        (EffectTarget::Sensor, other) => {
            return Err(DiagnoseError::SensorParam { name: other.into() })
        }
    })
}
