//! One diagnosis: calibrate, localize, assess every candidate (in parallel), close, decide.

use std::time::Instant;

use stirling_dsl::Model;

use super::blocks::{blocks, Blocks};
use super::candidates::candidates;
use super::context::{predict, Context, Eval, Prediction};
use super::gap::gap_before;
use super::types::{Diagnosis, RankEntry};
use super::{
    closure, joint, localize, rank, schedule, score, screen, sim_gap, verdict, DiagnoseError,
    DiagnoseOptions,
};
use crate::data::Measured;
use crate::effects::EffectInfo;
use crate::fit::free_run::SensorOffsets;
use crate::fit::{self, FitOptions, FittedStage, Identification};
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
    let (id, stages) = fit::identify_stages(model, p0, data, &calibration_options(opts, &b))?;
    let p_nom = nominal_params(model, p0, &id);
    let ctx = context(model, data, &b, &stages, p_nom.clone(), opts)?;
    let all: Vec<Prediction> = ctx.nominal_preds.iter().flatten().cloned().collect();
    let nominal = ctx.eval(&all, vec![], p_nom.clone())?;
    let s2 = variance_factors(&stages)?;
    let localization = localize::localize(data, &nominal, &ctx);
    report_progress(opts, || {
        format!(
            "nominal calibration done ({:.1} s); assessing {} candidate effects",
            clock.elapsed().as_secs_f64(),
            cands.len()
        )
    });
    let gap_before = gap_before(&ctx, &nominal, &stages);
    let nom = Nominal {
        stages: &stages,
        s2: &s2,
        eval: &nominal,
        absorbed: absorbed(&gap_before),
    };
    let assessed = assess_all(&ctx, &nom, &cands, opts, clock);
    let after = assessed.first().and_then(|a| a.eval.clone());
    let ranking: Vec<RankEntry> = assessed.into_iter().map(|a| a.entry).collect();
    let verdict = verdict::decide(
        &ranking,
        &nominal,
        opts.alpha,
        cands.len(),
        &gap_before.shifts,
    );
    let mut diagnosis = Diagnosis {
        simulation_gap: None,
        simulation_gap_note: None,
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
    };
    let nominal_run = NominalRun {
        offsets: &id.offsets,
        blocks: &b,
        p_nom: &p_nom,
    };
    attach_simulated_gap(&mut diagnosis, model, data, &nominal_run, opts);
    Ok(diagnosis)
}

/// The stages' variance factors.
fn variance_factors(stages: &[FittedStage]) -> Result<Vec<f64>, DiagnoseError> {
    Ok(stages
        .iter()
        .map(joint::variance_factor)
        .collect::<Result<Vec<f64>, _>>()?)
}

/// Whether a calibrated parameter moved beyond [`ABSORBED_SD`] prior deviations.
fn absorbed(gap: &super::types::GapBefore) -> bool {
    gap.shifts
        .iter()
        .any(|s| s.prior_sd.is_some_and(|z| z.abs() > ABSORBED_SD))
}

/// A progress line, when the caller asked for them.
fn report_progress(opts: &DiagnoseOptions, line: impl FnOnce() -> String) {
    if let Some(progress) = opts.progress {
        progress(&line());
    }
}

/// The options of the nominal calibration: the diagnosis's blocks, the stages without the
/// validation extras.
fn calibration_options(opts: &DiagnoseOptions, b: &Blocks) -> FitOptions {
    let mut fit_opts = opts.fit.clone();
    fit_opts.train = Some(b.train);
    fit_opts.holdout = Some(b.holdout);
    fit_opts.free_run = None;
    fit_opts.multiple_shooting = None;
    fit_opts.input_noise_draws = 0;
    fit_opts.prior = opts.prior;
    fit_opts
}

/// The calibrated parameters in the order of the model's parameter vector.
fn nominal_params(model: &dyn Model, p0: &[f64], id: &Identification) -> Vec<f64> {
    let mut p_nom = p0.to_vec();
    for (name, v) in &id.params {
        if let Some(i) = model.param_index(name) {
            p_nom[i] = *v;
        }
    }
    p_nom
}

/// The record, its blocks and noise, and the nominal stages' predictions.
fn context<'a>(
    model: &'a dyn Model,
    data: &'a Measured,
    b: &Blocks,
    stages: &[FittedStage],
    p_nom: Vec<f64>,
    opts: &DiagnoseOptions,
) -> Result<Context<'a>, DiagnoseError> {
    let noise: Vec<(String, f64)> = data
        .channels()
        .iter()
        .filter_map(|c| {
            data.channel(c)
                .map(|v| (c.to_string(), noise_sigma(v).max(1e-12)))
        })
        .collect();
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
        .collect::<Result<Vec<_>, _>>()?;
    let input_noise = stages
        .iter()
        .map(|st| {
            let (draws, seed) = (opts.noise_draws, opts.seed);
            st.stage
                .input_noise_draws(&st.u, st.first, st.last, &st.keep, draws, seed)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Context {
        model,
        data,
        noise,
        train_idx: b.train_idx,
        hold_idx: b.hold_idx,
        starts,
        half_period: period / 2,
        lag: score::bandwidth(b.train_idx.1 - b.train_idx.0, period),
        p_nom,
        nominal_preds,
        input_noise,
        fits: std::sync::atomic::AtomicUsize::new(1),
        progress: opts.progress,
    })
}

/// A calibrated parameter further than this many prior standard deviations from its start
/// says the calibration absorbed something (see [`assess_all`]).
const ABSORBED_SD: f64 = 2.0;

/// The nominal calibration as the candidates see it.
struct Nominal<'s, 'a> {
    stages: &'s [FittedStage<'a>],
    /// The stages' variance factors.
    s2: &'s [f64],
    eval: &'s Eval,
    /// Whether a calibrated parameter moved beyond [`ABSORBED_SD`] prior deviations.
    absorbed: bool,
}

/// A joint fit stops when an accepted step lowers the cost (half the chi-square of the
/// weighted residuals, which have unit variance) by less than this: 1/50 of the held-out BIC
/// change a verdict needs ([`verdict::STRONG_BIC`], in -2 log likelihood). On the lag record
/// of docs/diagnosis.md the fits' last iterations gained 0.01 to 0.3 each.
const JOINT_FATOL: f64 = 0.1;

/// Screen every candidate, fit the significant ones, rank them and attach the closure of
/// each fitted one. The candidates are independent: one per core.
///
/// Only a significant candidate can be the verdict ([`verdict::pick`]; the self-check's
/// tuning can only tighten the level), and the significant ones rank ahead of every other,
/// so fitting the others changes no verdict: they are fitted with `fit_all` only (for the
/// report). When the calibration moved a parameter beyond [`ABSORBED_SD`] prior deviations
/// the progress line says so: an effect may be absorbed there, and `--fit-all` shows how
/// each model effect fits from its own basin (the nominal parameters reset). On the lag
/// record of docs/diagnosis.md those fits were 18 of 77 CPU seconds.
fn assess_all(
    ctx: &Context,
    nom: &Nominal,
    cands: &[&'static EffectInfo],
    opts: &DiagnoseOptions,
    clock: Instant,
) -> Vec<rank::Assessed> {
    use rayon::prelude::*;
    let mut lm = opts.fit.lm;
    lm.max_iter = opts.joint_iters;
    // trial steps of at most one typical strength: far trials (an engine stopped by friction)
    // are slow to integrate and rejected anyway
    lm.max_step = 1.0;
    lm.fatol = JOINT_FATOL;
    let level = opts.alpha / cands.len().max(1) as f64;
    let (stages, s2, nominal) = (nom.stages, nom.s2, nom.eval);
    let screened: Vec<screen::Screened> = cands
        .par_iter()
        .map(|e| screen::screen_candidate(ctx, stages, s2, e))
        .collect();
    let fit = |s: &screen::Screened| opts.fit_all || s.significant(level);
    report_progress(opts, || {
        let sig = screened.iter().filter(|s| s.significant(level)).count();
        let fitted = screened.iter().filter(|s| fit(s)).count();
        screen_line(
            screened.len(),
            (sig, fitted, level),
            nom.absorbed,
            opts,
            clock,
        )
    });
    let mut assessed = schedule::longest_first(screened, |s| {
        if fit(&s) {
            let significant = s.significant(level);
            rank::assess(ctx, stages, s2, nominal, s, &lm, significant)
        } else {
            s.unfitted("not fitted: its score is not significant (--fit-all fits it)")
        }
    });
    rank::sort(&mut assessed, level);
    attach_closures(ctx, nominal, &mut assessed, opts);
    assessed
}

/// The progress line after the screen: how many candidates are significant, how many are
/// fitted, and why more are fitted than are significant.
fn screen_line(
    screened: usize,
    (sig, fitted, level): (usize, usize, f64),
    absorbed: bool,
    opts: &DiagnoseOptions,
    clock: Instant,
) -> String {
    let why = if opts.fit_all {
        " (--fit-all)"
    } else if absorbed && fitted < screened {
        " (the calibration moved a parameter beyond 2 prior sd: an effect may be absorbed there; --fit-all fits the others too)"
    } else {
        ""
    };
    format!(
        "screened {screened} candidates ({:.1} s): {sig} significant at {level:.1e}; fitting {fitted}{why}",
        clock.elapsed().as_secs_f64(),
    )
}

/// The driven closure, with its interval, of every fitted candidate.
fn attach_closures(
    ctx: &Context,
    nominal: &Eval,
    assessed: &mut [rank::Assessed],
    opts: &DiagnoseOptions,
) {
    for a in assessed.iter_mut() {
        if let Some(ev) = &a.eval {
            let c = closure::closure(
                ctx.data,
                nominal,
                ev,
                ctx.hold_idx,
                ctx,
                opts.bootstrap,
                opts.seed,
            );
            a.entry.closure_fraction = Some(c.fraction);
            a.entry.ci_low = Some(c.ci_low);
            a.entry.ci_high = Some(c.ci_high);
        }
    }
}

/// What the simulated gap needs of the nominal calibration.
struct NominalRun<'a> {
    offsets: &'a SensorOffsets,
    blocks: &'a Blocks,
    p_nom: &'a [f64],
}

/// The simulated gap before and after the leading fitted candidate (the sensor effects
/// distort the simulated outputs as they distort the data); when it cannot be computed, the
/// reason instead.
fn attach_simulated_gap(
    d: &mut Diagnosis,
    model: &dyn Model,
    data: &Measured,
    nominal: &NominalRun,
    opts: &DiagnoseOptions,
) {
    let before = sim_gap::Simulated {
        p: nominal.p_nom,
        tau_p: 0.0,
        gain: (0.0, 0.0),
    };
    let top = d.ranking.first().filter(|r| r.fitted);
    let value = |name: &str| {
        top.and_then(|r| r.params.iter().find(|q| q.name == name))
            .map_or(0.0, |q| q.value)
    };
    let effect = d.after.as_ref().zip(top).map(|(ev, r)| {
        (
            r.effect.as_str(),
            sim_gap::Simulated {
                p: &ev.p,
                tau_p: value("tau_p").max(0.0),
                gain: (value("gain_x"), value("gain_y")),
            },
        )
    });
    let sim = sim_gap::simulation_gap(
        model,
        data,
        nominal.offsets,
        nominal.blocks.holdout,
        &before,
        effect.as_ref().map(|(n, m)| (*n, m)),
        opts.bootstrap,
        opts.seed,
    );
    match sim {
        Ok(g) => d.simulation_gap = Some(g),
        Err(e) => d.simulation_gap_note = Some(e.to_string()),
    }
}
