//! The variables an effect adds to the calibrated stages: which stage each enters (a model
//! parameter by its parameter-Jacobian column, a sensor parameter by what the stage reads
//! and outputs), and the first-order link of a gas-stage effect into the mechanics stage.

use stirling_dsl::Model;

use super::memo::Memo;
use super::{is_mechanics, EffectAt, EffectVar};
use crate::diagnose::DiagnoseError;
use crate::effects::{EffectInfo, EffectTarget};
use crate::fit::sensitivity::Signal;
use crate::fit::vars::{Sensor, Var, VarKind};
use crate::fit::{classify, unmeasured, FittedStage};

/// The variables an effect adds to the nominal stages.
pub(super) struct EffectVars {
    pub effect: Vec<EffectVar>,
    /// Which stage each effect variable goes to, with its variable there.
    adds: Vec<(usize, Var)>,
    /// Signals the linked variables of the mechanics stage read (see [`link`]).
    linked: Vec<(usize, Vec<Signal>)>,
}

impl EffectVars {
    /// The variables of the effects accepted so far (`base`, their shapes free unless `held`) and of the
    /// candidates (their strengths and, with `free_shapes`, their shapes), and where they
    /// enter.
    pub fn of(
        model: &dyn Model,
        (nominal, memo): (&[FittedStage], &Memo),
        (base, held): (&[EffectAt], bool),
        cands: &[EffectAt],
        free_shapes: bool,
    ) -> Result<Self, DiagnoseError> {
        let mut v = EffectVars {
            effect: Vec::new(),
            adds: Vec::new(),
            linked: Vec::new(),
        };
        for a in base {
            v.add(
                model,
                (nominal, memo),
                a.effect,
                &a.shapes,
                (!a.shapes.is_empty() && !held, true),
            )?;
        }
        for c in cands {
            v.add(
                model,
                (nominal, memo),
                c.effect,
                &c.shapes,
                (free_shapes, false),
            )?;
        }
        cut_links(&mut v.adds);
        Ok(v)
    }

    /// Add the variables of one effect (`free_shapes`: fit its shapes; `base`: an accepted
    /// effect, a nuisance of the problem rather than its candidate).
    fn add(
        &mut self,
        model: &dyn Model,
        (nominal, memo): (&[FittedStage], &Memo),
        e: &EffectInfo,
        shapes: &[(&str, f64)],
        (free_shapes, base): (bool, bool),
    ) -> Result<(), DiagnoseError> {
        let n_nom: usize = nominal.iter().map(|s| s.stage.vars.len()).sum();
        let v = self;
        for q in e.params {
            let shape_value = shapes.iter().find(|(n, _)| *n == q.name).map(|s| s.1);
            let (initial, scale) = match (q.null, shape_value) {
                (Some(null), _) => (null, q.typical),
                (None, Some(val)) if free_shapes => (val, 0.1 * val.abs().max(1e-9)),
                _ => continue,
            };
            // a range the model declares for the parameter (`in lo..hi`)
            let range = model
                .param_index(q.name)
                .and_then(|j| crate::fit::vars::param_bounds(model, j, &[]));
            v.effect.push(EffectVar {
                range,
                name: q.name.into(),
                index: n_nom + v.effect.len(),
                null: initial,
                scale,
                bounded: q.null.is_some() && !q.name.starts_with("gain"),
                shape: q.null.is_none(),
                base,
                unit: q.unit.into(),
            });
            for (si, st) in nominal.iter().enumerate() {
                if let Some(kind) = kind_in(model, st, e, q.name)? {
                    let var = Var {
                        name: q.name.into(),
                        initial,
                        scale,
                        kind,
                        prior: None,
                        bounds: range,
                    };
                    v.adds.push((si, var));
                }
            }
            cut_gain(nominal, &mut v.adds, q.name);
            if let Some((si, var, sigs)) = link((nominal, memo), &v.adds, &v.linked, q.name)? {
                v.adds.push((si, var));
                v.linked.push((si, sigs));
            }
            if !v.adds.iter().any(|(_, var)| var.name == q.name) {
                return Err(DiagnoseError::NotDriven {
                    param: q.name.into(),
                    model: model.name().into(),
                });
            }
        }
        Ok(())
    }

    /// Nominal stage `si` extended by the effect's variables, with the joint index of each
    /// of its variables; `None` when the effect leaves the stage alone.
    pub fn extend<'a>(
        &self,
        model: &dyn Model,
        nominal: &[FittedStage],
        si: usize,
        st: &FittedStage<'a>,
        shapes: &[(&str, f64)],
    ) -> Option<(FittedStage<'a>, Vec<usize>)> {
        let extra: Vec<&Var> = self
            .adds
            .iter()
            .filter(|(s, _)| *s == si)
            .map(|(_, v)| v)
            .collect();
        if extra.is_empty() {
            return None;
        }
        let mut ext = st.clone();
        for (_, sigs) in self.linked.iter().filter(|(s, _)| *s == si) {
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
        for v in extra {
            let k = self.effect.iter().find(|ev| ev.name == v.name)?.index;
            m.push(k);
            ext.stage.vars.push(v.clone());
            ext.u.push(0.0);
        }
        Some((ext, m))
    }
}

/// A position gain that the gas stage reads its prescribed positions through is estimated
/// there alone: in a mechanics stage that reads the gas stage's pressure differences
/// (records without `p_hot`) the gain `name` is a given value (unit 0: no column), set to the
/// gas stage's at every rebase ([`super::Joint::rebase`]). A cut estimator: stage 1 applies
/// the gain to its position outputs but does not inform it. Why: stage 1's `x` rows cannot
/// tell a gain from the displacer's own amplitude response, and fitted jointly they pulled
/// `gain_x` to -7.3 % on a +5 % record (docs/diagnosis.md, "A position gain estimated where
/// it is seen").
fn cut_gain(nominal: &[FittedStage], adds: &mut [(usize, Var)], name: &str) {
    let read_by_gas = adds.iter().any(|(s, v)| {
        v.name == name
            && !is_mechanics(&nominal[*s])
            && matches!(&v.kind, VarKind::Sensor(Sensor::Gain { given, .. }) if !given.is_empty())
    });
    if !read_by_gas {
        return;
    }
    for (s, v) in adds.iter_mut() {
        let st = &nominal[*s];
        if v.name == name
            && is_mechanics(st)
            && !st.stage.derived.is_empty()
            && matches!(v.kind, VarKind::Sensor(Sensor::Gain { .. }))
        {
            v.scale = 0.0;
        }
    }
}

/// With a cut gain in the problem, the effect strengths linked into the mechanics stage are
/// cut too (unit 0: stage 1 applies them through the differences the rebase computes at the
/// gas stage's values, but does not inform them): the problem is then the calibration's
/// two-step estimator throughout. Why: the gas stage's rows confound a leak with the gain on
/// `x` (both set the pressure swing), so a leak that stage 1 informs through its link moves
/// the gain in the gas stage at every round, and the rounds diverged (leak + gain from the
/// nominal calibration, self-check case 49: `gain_x` 6.3 %, -7.2 %, -53 %, cost 2451, 1975,
/// 2533, 7.1e6).
fn cut_links(adds: &mut [(usize, Var)]) {
    let cut = adds
        .iter()
        .any(|(_, v)| v.scale == 0.0 && matches!(v.kind, VarKind::Sensor(Sensor::Gain { .. })));
    if !cut {
        return;
    }
    for (_, v) in adds.iter_mut() {
        if matches!(v.kind, VarKind::Linked { .. }) {
            v.scale = 0.0;
        }
    }
}

/// On records without `p_hot` the mechanics stage reads the gas stage's pressure differences
/// ([`crate::fit::unmeasured`]); a gas-stage effect (quadratic regenerator friction, a leak)
/// changes them, so the mechanics stage gets the effect too, linked to first order: its
/// prescribed pressures move by `(value - null) dP/dvalue`, the derivative from the gas
/// stage's forward sensitivities at the nominal optimum. Returns the mechanics stage, its
/// variable and the derivative signals (appended after those already queued in `linked`).
fn link(
    (nominal, memo): (&[FittedStage], &Memo),
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
    // a function of the nominal gas stage and the variable alone (its start and unit)
    let key = format!(
        "{}:{:x}:{:x}",
        gvar.name,
        gvar.initial.to_bits(),
        gvar.scale.to_bits()
    );
    let d = memo.link(&key, || {
        unmeasured::difference_sensitivity(&st, &u, st.vars.len() - 1, gas.first)
    })?;
    let cold = d.len() - 1;
    let queued: usize = linked
        .iter()
        .filter(|(s, _)| *s == mech)
        .map(|(_, v)| v.len())
        .sum();
    let base = nominal[mech].stage.signals.len() + queued;
    let var = Var {
        kind: VarKind::Linked {
            pairs: (0..cold).map(|i| (i, base + i)).collect(),
            at: gvar.initial,
        },
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
    match e.target {
        EffectTarget::Model => model_kind(model, st, e, name),
        // named on one sensor (`effect lag on sensor p_bounce;`)
        EffectTarget::Sensor if matches!(e.name, "lag" | "gain") => {
            let s = one_sensor(st, name)
                .ok_or_else(|| DiagnoseError::SensorParam { name: name.into() })?;
            // a stage that neither reads nor outputs the sensor does not see it
            let acts = match &s {
                Sensor::Lag { signals, outputs } => !signals.is_empty() || !outputs.is_empty(),
                Sensor::Gain { given, outputs } => !given.is_empty() || !outputs.is_empty(),
            };
            Ok(acts.then_some(VarKind::Sensor(s)))
        }
        EffectTarget::Sensor => sensor_kind(st, name).map(Some),
    }
}

/// A model parameter of an effect enters a stage when its column of the parameter
/// Jacobian is nonzero there, with the effect's strengths on and its shapes (travel,
/// smoothing) small, so that it acts at the probe state [`classify`] uses. A shape
/// parameter enters where its strengths do.
fn model_kind(
    model: &dyn Model,
    st: &FittedStage,
    e: &EffectInfo,
    name: &str,
) -> Result<Option<VarKind>, DiagnoseError> {
    let j = model
        .param_index(name)
        .ok_or_else(|| DiagnoseError::UnknownParameter {
            name: name.into(),
            model: model.name().into(),
        })?;
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
    let mech = is_mechanics(st);
    let enters = probe.iter().any(|q| {
        classify(model, &p, std::slice::from_ref(q)).is_ok_and(|(m, g)| {
            if mech {
                !m.is_empty()
            } else {
                !g.is_empty()
            }
        })
    });
    Ok(enters.then_some(VarKind::Param(j)))
}

/// The sensor distortion a sensor parameter is in a stage: a lag on the measured pressures
/// (stage 1 reads them, stage 2 outputs them), a gain on a measured position (stage 1
/// outputs it, stage 2 reads it).
fn sensor_kind(st: &FittedStage, name: &str) -> Result<VarKind, DiagnoseError> {
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
    let sensor = match name {
        "tau_p" if mech => Sensor::Lag {
            // the measured pressures only, not the model's pressure differences
            signals: (0..st.stage.signals.len())
                .filter(|s| !st.stage.derived.contains(s))
                .collect(),
            outputs: vec![],
        },
        "tau_p" => Sensor::Lag {
            signals: vec![],
            outputs: outputs(&|c| c.starts_with('p')),
        },
        "gain_x" | "gain_y" if mech => Sensor::Gain {
            given: vec![],
            outputs: outputs(&|c| c == &name[5..]),
        },
        "gain_x" | "gain_y" => {
            // stage 2 reads the positions as signals 0 (x) and 1 (y)
            let sig = usize::from(name == "gain_y");
            let given = st
                .stage
                .given
                .iter()
                .enumerate()
                .filter(|(_, g)| g.terms.iter().any(|t| t.0 == sig))
                .map(|(i, _)| i)
                .collect();
            Sensor::Gain {
                given,
                outputs: vec![],
            }
        }
        other => return Err(DiagnoseError::SensorParam { name: other.into() }),
    };
    Ok(VarKind::Sensor(sensor))
}

/// A distortion named on one sensor (`effect lag on sensor p_bounce;` gives `tau_p_bounce`,
/// `effect gain on sensor x;` `gain_x`): in a stage that prescribes the sensor's state, on
/// what prescribes it (a lag un-lags its measured signals, a gain divides it); in a stage
/// that outputs the channel, on that output.
fn one_sensor(st: &FittedStage, name: &str) -> Option<Sensor> {
    let (lag, channel) = match (name.strip_prefix("tau_"), name.strip_prefix("gain_")) {
        (Some(ch), _) => (true, ch),
        (_, Some(ch)) => (false, ch),
        _ => return None,
    };
    let stage = &st.stage;
    stage.model.sensors().iter().find(|s| s.name == channel)?;
    let state = stage.model.sensor_state(channel).flatten();
    // the measured signals that prescribe the sensor's state
    let mut signals: Vec<usize> = stage
        .given
        .iter()
        .filter(|g| Some(g.state) == state)
        .flat_map(|g| g.terms.iter().map(|t| t.0))
        .filter(|s| !stage.derived.contains(s))
        .collect();
    signals.sort_unstable();
    signals.dedup();
    let outputs: Vec<usize> = (0..stage.outputs.len())
        .filter(|&o| stage.outputs[o].channel == channel)
        .collect();
    Some(if lag {
        Sensor::Lag { signals, outputs }
    } else {
        // every prescribed state read from those signals (a position and its velocity)
        let given = (0..stage.given.len())
            .filter(|&g| stage.given[g].terms.iter().any(|t| signals.contains(&t.0)))
            .collect();
        Sensor::Gain { given, outputs }
    })
}
