//! One diagnosis: calibrate, localize, assess every candidate (in parallel), close, decide.

use std::time::Instant;

use stirling_dsl::Model;

use super::blocks::blocks;
use super::candidates::candidates;
use super::context::{predict, Context, Prediction};
use super::gap::gap_before;
use super::types::{Diagnosis, RankEntry};
use super::{
    closure, joint, localize, rank, score, sim_gap, verdict, DiagnoseError, DiagnoseOptions,
};
use crate::data::Measured;
use crate::fit;
use crate::signal::noise_sigma;

/// Diagnose `model` (a base model with an augmented member: `cv1`, `nsection`) from starting
/// parameters `p0` (of the augmented model, effects at their nulls) on a measured record.
pub fn diagnose(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    let b = blocks(data, opts)?;
    let cands = candidates(model, &opts.effects)?;
    let noise: Vec<(String, f64)> = data
        .channels()
        .iter()
        .filter_map(|c| {
            data.channel(c)
                .map(|v| (c.to_string(), noise_sigma(v).max(1e-12)))
        })
        .collect();
    let mut fit_opts = opts.fit.clone();
    fit_opts.train = Some(b.train);
    fit_opts.holdout = Some(b.holdout);
    // the diagnosis needs the stages, not the validation extras
    fit_opts.free_run = None;
    fit_opts.multiple_shooting = None;
    fit_opts.input_noise_draws = 0;
    fit_opts.prior = opts.prior;
    let (id, stages) = fit::identify_stages(model, p0, data, &fit_opts)
        .map_err(|e| DiagnoseError::Nominal(e.to_string()))?;
    let mut p_nom = p0.to_vec();
    for (name, v) in &id.params {
        if let Some(i) = model.param_index(name) {
            p_nom[i] = *v;
        }
    }
    let starts = crate::signal::cycle_starts(data, (b.train_idx.0, b.hold_idx.1));
    let period = if starts.len() >= 2 {
        (starts[starts.len() - 1] - starts[0]) / (starts.len() - 1)
    } else {
        0
    };
    let last = b.hold_idx.1 - 1;
    let nominal_preds = stages
        .iter()
        .map(|st| predict(st, &st.u, last))
        .collect::<Result<Vec<_>, String>>()
        .map_err(DiagnoseError::Nominal)?;
    let ctx = Context {
        model,
        data,
        noise,
        train_idx: b.train_idx,
        hold_idx: b.hold_idx,
        half_period: period / 2,
        lag: score::bandwidth(b.train_idx.1 - b.train_idx.0, period),
        p_nom: p_nom.clone(),
        nominal_preds,
        input_noise: stages
            .iter()
            .map(|st| {
                st.stage.input_noise_draws(
                    &st.u,
                    st.first,
                    st.last,
                    &st.keep,
                    opts.noise_draws,
                    opts.seed,
                )
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| DiagnoseError::Nominal(e.to_string()))?,
        fits: std::sync::atomic::AtomicUsize::new(1),
        progress: opts.progress,
    };
    let all: Vec<Prediction> = ctx.nominal_preds.iter().flatten().cloned().collect();
    let nominal = ctx
        .eval(&all, vec![], p_nom.clone())
        .map_err(DiagnoseError::Nominal)?;
    let s2 = stages
        .iter()
        .map(joint::variance_factor)
        .collect::<Result<Vec<f64>, _>>()
        .map_err(|e| DiagnoseError::Nominal(e.to_string()))?;
    let localization = localize::localize(model, &p_nom, data, &nominal, &ctx);
    if let Some(progress) = opts.progress {
        progress(&format!(
            "nominal calibration done ({:.1} s); assessing {} candidate effects",
            clock.elapsed().as_secs_f64(),
            cands.len()
        ));
    }
    let mut lm = opts.fit.lm;
    lm.max_iter = opts.joint_iters;
    // trial steps of at most one typical strength: far trials (an engine stopped by friction)
    // are slow to integrate and rejected anyway
    lm.max_step = 1.0;
    // the candidates are independent: one per core. First the score screens (one residual
    // and Jacobian each); then the joint fits, of the significant candidates only (the
    // verdict names only a significant one), or of all with `fit_all`
    let level = opts.alpha / cands.len().max(1) as f64;
    let mut assessed: Vec<rank::Assessed> = {
        use rayon::prelude::*;
        let screened: Vec<rank::Screened> = cands
            .par_iter()
            .map(|e| rank::screen_candidate(&ctx, &stages, &s2, e))
            .collect();
        if let Some(progress) = opts.progress {
            let sig = screened.iter().filter(|s| s.significant(level)).count();
            progress(&format!(
                "screened {} candidates ({:.1} s): {sig} significant at {level:.1e}{}",
                screened.len(),
                clock.elapsed().as_secs_f64(),
                if opts.fit_all { "; fitting all" } else { "" }
            ));
        }
        screened
            .into_par_iter()
            .map(|s| {
                if opts.fit_all || s.significant(level) {
                    rank::assess(&ctx, &stages, &s2, &nominal, s, &lm)
                } else {
                    s.unfitted("not fitted: its score is not significant (--fit-all fits it)")
                }
            })
            .collect()
    };
    rank::sort(&mut assessed, level);
    for a in assessed.iter_mut() {
        if let Some(ev) = &a.eval {
            let c = closure::closure(
                data,
                &nominal,
                ev,
                ctx.hold_idx,
                &ctx,
                opts.bootstrap,
                opts.seed,
            );
            a.entry.closure_fraction = Some(c.fraction);
            a.entry.ci_low = Some(c.ci_low);
            a.entry.ci_high = Some(c.ci_high);
        }
    }
    let after = assessed.first().and_then(|a| a.eval.clone());
    let ranking: Vec<RankEntry> = assessed.into_iter().map(|a| a.entry).collect();
    let gap_before = gap_before(&ctx, &nominal, &stages, &localization);
    let verdict = verdict::decide(
        &ranking,
        &nominal,
        opts.alpha,
        cands.len(),
        &gap_before.shifts,
    );
    let (simulation_gap, simulation_gap_note) = match simulated_gap(
        model,
        data,
        &id.offsets,
        &b,
        &p_nom,
        &ranking,
        after.as_ref(),
        opts,
    ) {
        Ok(g) => (Some(g), None),
        Err(e) => (None, Some(e.to_string())),
    };
    Ok(Diagnosis {
        simulation_gap,
        simulation_gap_note,
        model: model.name().into(),
        n: model.n(),
        train: b.train,
        holdout: b.holdout,
        gap_before,
        localization,
        ranking,
        verdict,
        fits: ctx.fits.load(std::sync::atomic::Ordering::Relaxed),
        seconds: clock.elapsed().as_secs_f64(),
        before: Some(nominal),
        after,
    })
}

/// The simulated gap before and after the leading fitted candidate (the sensor effects
/// distort the simulated outputs as they distort the data).
#[allow(clippy::too_many_arguments)]
fn simulated_gap(
    model: &dyn Model,
    data: &Measured,
    offsets: &crate::fit::free_run::SensorOffsets,
    b: &super::blocks::Blocks,
    p_nom: &[f64],
    ranking: &[RankEntry],
    after: Option<&super::context::Eval>,
    opts: &DiagnoseOptions,
) -> Result<sim_gap::SimulationGap, sim_gap::SimGapError> {
    let before = sim_gap::Simulated {
        p: p_nom,
        tau_p: 0.0,
        gain: (0.0, 0.0),
    };
    let top = ranking.first().filter(|r| r.fitted);
    let value = |name: &str| {
        top.and_then(|r| r.params.iter().find(|q| q.name == name))
            .map_or(0.0, |q| q.value)
    };
    let effect = after.zip(top).map(|(ev, r)| {
        (
            r.effect.as_str(),
            sim_gap::Simulated {
                p: &ev.p,
                tau_p: value("tau_p").max(0.0),
                gain: (value("gain_x"), value("gain_y")),
            },
        )
    });
    sim_gap::simulation_gap(
        model,
        data,
        offsets,
        b.holdout,
        &before,
        effect.as_ref().map(|(n, m)| (*n, m)),
        opts.bootstrap,
        opts.seed,
    )
}
