//! One diagnosis: calibrate, localize, assess every candidate (in parallel), close, decide.

use std::time::Instant;

use stirling_dsl::Model;

use super::blocks::{blocks, Blocks};
use super::candidates::candidates;
use super::context::{predict, Context, Prediction};
use super::gap::gap_before;
use super::stops_equation::StopSide;
use super::types::{Diagnosis, EffectEstimate};
use super::{
    free_run_check, joint, localize, score, sim_gap, steps, verdict, DiagnoseError, DiagnoseOptions,
};
use crate::data::Measured;
use crate::fit::free_run::SensorOffsets;
use crate::fit::{self, FitOptions, FittedStage, Identification};
use crate::signal::noise_sigma;

/// Diagnose `model` (a base model with an augmented member: `cv1`, `nsection`) from starting
/// parameters `p0` (of the augmented model, effects at their nulls) on a measured record;
/// when the gap stays unexplained after a calibration that absorbed something, the end stops
/// are tried again with stage 1 restarted ([`super::restarted`]).
pub fn diagnose(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    if !crate::layout::StateLayout::flywheels(model).is_empty() {
        return super::kinematic::diagnose(model, p0, data, opts);
    }
    let mut opts = opts.clone();
    (opts.fit.sim.rtol, opts.fit.sim.atol) = (opts.rtol, opts.rtol);
    let opts = &opts;
    let seen = super::restarted::stops_seen(data, opts);
    let first = diagnose_once(model, p0, data, opts, &seen)?;
    let mut d = super::restarted::second_pass(model, p0, data, opts, (&first, &seen))
        .map_or(first, |second| *second);
    d.seconds = clock.elapsed().as_secs_f64();
    Ok(d)
}

/// One pass of the diagnosis with `opts` as given; on the restarted pass the end stops
/// `seen` in the measured acceleration hold their travels ([`super::restarted`]), on the
/// one-run pass the channels they do not touch judge the candidates too
/// ([`super::untouched`]).
pub(super) fn diagnose_once(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &DiagnoseOptions,
    seen: &[StopSide],
) -> Result<Diagnosis, DiagnoseError> {
    let clock = Instant::now();
    let b = blocks(data, opts)?;
    let cands = candidates(model, &opts.effects)?;
    let (id, stages) = fit::identify_stages(model, p0, data, &calibration_options(opts, &b))?;
    let calibrated = clock.elapsed().as_secs_f64();
    let p_nom = nominal_params(model, p0, &id);
    let mut ctx = context(model, data, &b, &stages, p_nom.clone(), opts)?;
    if ctx.restarted {
        ctx.held_travels = held_travels(seen, &id.offsets);
    } else {
        ctx.untouched = super::untouched::channels(&ctx.nominal_preds, seen);
    }
    let all: Vec<Prediction> = ctx.nominal_preds.iter().flatten().cloned().collect();
    let nominal = ctx.eval(&all, vec![], p_nom.clone())?;
    let s2 = variance_factors(&stages)?;
    let localization = localize::localize(data, &nominal, &ctx);
    super::assess::report(opts, || {
        format!(
            "nominal calibration done ({:.1} s; its predictions and the input noise's {} draws {:.1} s of it); assessing {} candidate effects",
            clock.elapsed().as_secs_f64(),
            opts.noise_draws,
            clock.elapsed().as_secs_f64() - calibrated,
            cands.len()
        )
    });
    let gap_before = gap_before(&ctx, &nominal, &stages);
    let absorbed = absorbed(&gap_before);
    let ex = steps::explain(
        &ctx,
        (&stages, &s2),
        &nominal,
        &cands,
        opts,
        (absorbed, clock),
    );
    let verdict = verdict::decide_steps(
        (&ex.steps, &ex.first, &ex.last),
        &nominal,
        opts.alpha,
        cands.len(),
        &gap_before.shifts,
    );
    let after = ex
        .steps
        .last()
        .and_then(|s| s.eval.clone())
        .or(ex.first_eval);
    let mut diagnosis = Diagnosis {
        simulation_gap: None,
        simulation_gap_note: None,
        model: model.name().into(),
        n: model.n(),
        train: b.train,
        holdout: b.holdout,
        gap_before,
        localization,
        ranking: ex.first,
        steps: ex.steps,
        remainder: ex.last,
        verdict,
        flywheel: None,
        stops_seen: Vec::new(),
        one_run: Vec::new(),
        fits: ctx.fits.load(std::sync::atomic::Ordering::Relaxed),
        seconds: 0.0,
        before: Some(nominal),
        after,
    };
    let nominal_run = NominalRun {
        offsets: &id.offsets,
        blocks: &b,
        p_nom: &p_nom,
    };
    attach_simulated_gaps(&mut diagnosis, model, data, &nominal_run, opts);
    free_run_check::flag(&mut diagnosis);
    diagnosis.seconds = clock.elapsed().as_secs_f64();
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
pub(super) fn absorbed(gap: &super::types::GapBefore) -> bool {
    gap.shifts
        .iter()
        .any(|s| s.prior_sd.is_some_and(|z| z.abs() > ABSORBED_SD))
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
        restarted: opts.fit.restart_cycles.is_some(),
        held_travels: Vec::new(),
        untouched: Vec::new(),
        progress: opts.progress,
    })
}

/// The end-stop travels `seen` in the measured acceleration, in the model's coordinates (the
/// travel less the calibrated position offset, as a distance).
fn held_travels(seen: &[StopSide], offsets: &SensorOffsets) -> Vec<(&'static str, f64)> {
    seen.iter()
        .map(|s| match s.channel.as_str() {
            "x" => ("xmax", (s.travel - offsets.x).abs()),
            _ => ("ymax", (s.travel - offsets.y).abs()),
        })
        .collect()
}

/// A calibrated parameter further than this many prior standard deviations from its start
/// says the calibration absorbed something (see [`assess_all`]).
const ABSORBED_SD: f64 = 2.0;

/// What the simulated gap needs of the nominal calibration.
struct NominalRun<'a> {
    offsets: &'a SensorOffsets,
    blocks: &'a Blocks,
    p_nom: &'a [f64],
}

/// The simulated gap before and after each step (the sensor effects distort the simulated
/// outputs as they distort the data), the last one's (or, without steps, the leading fitted
/// candidate's) as the diagnosis's; when it cannot be computed, the reason instead.
fn attach_simulated_gaps(
    d: &mut Diagnosis,
    model: &dyn Model,
    data: &Measured,
    nominal: &NominalRun,
    opts: &DiagnoseOptions,
) {
    for k in 0..d.steps.len() {
        let step = &d.steps[k];
        let Some(ev) = step.eval.as_ref() else {
            continue;
        };
        let label = step.effects.join(" + ");
        let sim = simulated_gap(
            model,
            data,
            nominal,
            opts,
            Some((&label, &ev.p, &step.params)),
        );
        let step = &mut d.steps[k];
        match sim {
            Ok(g) => step.simulation_gap = Some(g),
            Err(e) => step.simulation_gap_note = Some(e.to_string()),
        }
    }
    if let Some(last) = d.steps.last() {
        d.simulation_gap = last.simulation_gap.clone();
        d.simulation_gap_note = last.simulation_gap_note.clone();
        return;
    }
    let top = d.ranking.first().filter(|r| r.fitted);
    let effect = d
        .after
        .as_ref()
        .zip(top)
        .map(|(ev, r)| (r.effect.as_str(), ev.p.as_slice(), r.params.as_slice()));
    match simulated_gap(model, data, nominal, opts, effect) {
        Ok(g) => d.simulation_gap = Some(g),
        Err(e) => d.simulation_gap_note = Some(e.to_string()),
    }
}

/// The simulated gap of the calibrated model, and of the model after the effects whose
/// parameters `p` and estimates (the sensor distortions among them) are given.
fn simulated_gap(
    model: &dyn Model,
    data: &Measured,
    nominal: &NominalRun,
    opts: &DiagnoseOptions,
    effect: Option<(&str, &[f64], &[EffectEstimate])>,
) -> Result<sim_gap::SimulationGap, sim_gap::SimGapError> {
    let before = sim_gap::Simulated {
        p: nominal.p_nom,
        tau_p: 0.0,
        gain: (0.0, 0.0),
    };
    let after = effect.map(|(name, p, params)| {
        let value = |n: &str| params.iter().find(|q| q.name == n).map_or(0.0, |q| q.value);
        (
            name,
            sim_gap::Simulated {
                p,
                tau_p: value("tau_p").max(0.0),
                gain: (value("gain_x"), value("gain_y")),
            },
        )
    });
    sim_gap::simulation_gap(
        model,
        data,
        nominal.offsets,
        nominal.blocks.holdout,
        &before,
        after.as_ref().map(|(n, m)| (*n, m)),
        opts.bootstrap,
        opts.seed,
    )
}
