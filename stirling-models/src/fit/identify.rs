//! The two-stage identification: stage 1 (mechanics, [`super::mechanics`]) and stage 2 (gas,
//! [`super::gas`]) in turn, then the optional multiple-shooting refinement and the free-run
//! validation.
//!
//! When the model has several CVs and the record has no hot-side pressure, stage 1 runs twice:
//! first on the measured `p` alone (for the position offsets stage 2 needs), then, after
//! stage 2, on `p` plus the gas stage's pressure differences ([`super::unmeasured`]), with
//! the covariance that stage 2's uncertainty carries in.

use std::time::Instant;

use stirling_dsl::Model;

use super::classify::{classify, default_free};
use super::driven::Stage;
use super::gas::{self, GasStage};
use super::mechanics::{self, MechInputs};
use super::record::Record;
use super::sensitivity::Signal;
use super::stage_fit::{fit_stage, stats, FittedStage, Solved};
use super::vars::VarKind;
use super::{free_run, multiple_shooting, unmeasured};
use super::{FitError, FitOptions, Identification};
use crate::data::Measured;
use crate::layout::StateLayout;

/// The two-stage identification of `model` (starting from `p0`) on a measured record.
pub fn identify(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &FitOptions,
) -> Result<Identification, FitError> {
    identify_stages(model, p0, data, opts).map(|(id, _)| id)
}

/// Everything the stages share while they run.
struct Run<'a, 'r> {
    model: &'a dyn Model,
    layout: StateLayout,
    rec: Record<'r>,
    opts: &'r FitOptions,
    p0: Vec<f64>,
}

impl<'a> Run<'a, '_> {
    /// Fit stage 1 at parameters `p` with the given offsets and pressure differences.
    fn mechanics(
        &self,
        p: &[f64],
        free: &[usize],
        x_off: [f64; 2],
        p_off: (f64, f64),
        dp: Option<&[Signal]>,
    ) -> Result<(Stage<'a>, Solved), FitError> {
        let inp = MechInputs {
            p,
            free,
            x_off,
            p_off: p_off.0,
            ph_off: p_off.1,
            dp,
        };
        let stage = mechanics::stage(self.model, &self.layout, &self.rec, &inp, self.opts)?;
        let solved = fit_stage(&stage, self.rec.tr, self.rec.ho, 0, self.opts)?;
        Ok((stage, solved))
    }

    /// Fit stage 2 at parameters `p`.
    fn gas(
        &self,
        p: &[f64],
        free: &[usize],
        x_off: [f64; 2],
    ) -> Result<(GasStage<'a>, Solved), FitError> {
        let gs = gas::stage(
            self.model,
            &self.layout,
            &self.rec,
            p,
            free,
            x_off,
            self.opts,
        )?;
        let solved = fit_stage(&gs.stage, self.rec.tr, self.rec.ho, gs.burn, self.opts)?;
        Ok((gs, solved))
    }

    /// The fitted stage record for the diagnosis.
    fn fitted(&self, stage: Stage<'a>, solved: &Solved) -> FittedStage<'a> {
        FittedStage {
            stage,
            u: solved.lm.x.clone(),
            first: self.rec.tr.0,
            last: self.rec.tr.1,
            keep: solved.keep.clone(),
        }
    }
}

/// Copy a stage's fitted model parameters into `p`; returns the fitted offsets by output.
fn apply(stage: &Stage, values: &[f64], p: &mut [f64]) -> Vec<(usize, f64)> {
    let mut offs = Vec::new();
    for (v, val) in stage.vars.iter().zip(values) {
        match v.kind {
            VarKind::Param(j) => p[j] = *val,
            VarKind::Offset { out, .. } => offs.push((out, *val)),
            _ => {}
        }
    }
    offs
}

/// [`identify`], also returning the fitted stages (stage 1, then stage 2, those that ran).
pub fn identify_stages<'a>(
    model: &'a dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &FitOptions,
) -> Result<(Identification, Vec<FittedStage<'a>>), FitError> {
    let clock = Instant::now();
    let layout = StateLayout::of(model);
    let rec = Record::new(model, &layout, p0, data, opts)?;
    let free = opts.free.clone().unwrap_or_else(|| default_free(model, p0));
    let (mech, gas_free) = classify(model, p0, &free)?;
    let run = Run {
        model,
        layout,
        rec,
        opts,
        p0: p0.to_vec(),
    };
    let rec = &run.rec;
    let mut p = p0.to_vec();
    let mut x_off = rec.x_off0;
    let (mut p_off, mut ph_off) = (rec.p_off0, rec.ph_off0);
    let run1 = opts.stage1 && !mech.is_empty();
    let estimate_dp = run1 && !rec.have_hot && run.layout.pressures.len() > 1;
    let run2 = (opts.stage2 && !gas_free.is_empty()) || estimate_dp;
    let mut fitted = Vec::new();
    let (mut stage1, mut stage2) = (None, None);

    if run1 {
        let (st, solved) = run.mechanics(&p, &mech, x_off, (p_off, ph_off), None)?;
        for (out, v) in apply(&st, &solved.values, &mut p) {
            x_off[out] = v;
        }
        if !estimate_dp {
            stage1 = Some(solved.fit.clone());
            fitted.push(run.fitted(st, &solved));
        }
    }
    let mut gas_fit = None;
    if run2 {
        let free2 = if opts.stage2 {
            gas_free.clone()
        } else {
            Vec::new()
        };
        let (gs, solved) = run.gas(&p, &free2, x_off)?;
        for (out, v) in apply(&gs.stage, &solved.values, &mut p) {
            if out == 0 {
                p_off = v;
            } else {
                ph_off = v;
            }
        }
        x_off = gs.position_offsets(x_off, p_off, ph_off);
        if opts.stage2 {
            stage2 = Some(solved.fit.clone());
        }
        gas_fit = Some((gs, solved));
    }
    if estimate_dp {
        let (gs, s2) = gas_fit.as_ref().expect("stage 2 ran");
        let dp = unmeasured::pressure_differences(&gs.stage, &s2.lm.x, &run.layout, rec)?;
        for &j in &mech {
            p[j] = run.p0[j];
        }
        let (st, mut solved) = run.mechanics(&p, &mech, x_off, (p_off, ph_off), Some(&dp))?;
        let carried = unmeasured::carried_covariance(
            &st,
            &solved.lm.x,
            &solved.lm.jacobian,
            &solved.keep,
            &gs.stage,
            &s2.lm.x,
            &s2.fit.stats,
            &run.layout,
            rec,
        )?;
        let extra = match (&solved.noise_cov, carried) {
            (Some(a), Some(b)) => Some(a + b),
            (a, b) => a.clone().or(b),
        };
        solved.fit.stats = stats(&st, &solved.lm, extra.as_ref());
        for (out, v) in apply(&st, &solved.values, &mut p) {
            x_off[out] = v;
        }
        stage1 = Some(solved.fit.clone());
        fitted.push(run.fitted(st, &solved));
    }
    if let Some((gs, s2)) = gas_fit.filter(|_| opts.stage2) {
        fitted.push(run.fitted(gs.stage, &s2));
    }
    let mut offsets = free_run::SensorOffsets {
        x: x_off[0],
        y: x_off[1],
        p: p_off,
        p_hot: rec.have_hot.then_some(ph_off),
    };
    let mut notes = Vec::new();
    let mut ms = None;
    if let Some(mo) = &opts.multiple_shooting {
        let mut idx_free: Vec<usize> = mech.clone();
        idx_free.extend(gas_free.iter().filter(|j| !mech.contains(j)));
        match multiple_shooting::multiple_shooting(
            model, &p, &idx_free, data, &offsets, rec.train, mo,
        ) {
            Ok(r) => {
                for (k, (_, v)) in r.params.iter().enumerate() {
                    p[k] = *v;
                }
                offsets = r.offsets.clone();
                ms = Some(r);
            }
            Err(e) => notes.push(format!("multiple shooting: {e}")),
        }
    }
    let mut fr = None;
    if let Some(fo) = &opts.free_run {
        let block = rec.holdout.unwrap_or(rec.train);
        match free_run::free_run(model, &p, data, &offsets, block, fo) {
            Ok(r) => fr = Some(r),
            Err(e) => notes.push(format!("free run: {e}")),
        }
    }
    let id = Identification {
        model: model.name().into(),
        n: model.n(),
        params: crate::params::named(model, &p),
        stage1,
        stage2,
        train: rec.train,
        holdout: rec.holdout,
        seconds: clock.elapsed().as_secs_f64(),
        offsets,
        multiple_shooting: ms,
        free_run: fr,
        notes,
    };
    Ok((id, fitted))
}
