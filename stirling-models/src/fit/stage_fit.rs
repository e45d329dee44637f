//! Fitting one driven stage: Levenberg-Marquardt on the training samples, the statistics
//! (with the input-noise covariance and any covariance carried in from another stage), and
//! the fit percentages on the training and held-out blocks.

use std::time::Instant;

use nalgebra::DMatrix;

use super::driven::Stage;
use super::lm::{self, LmResult};
use super::report::{self, fit_percent, ChannelFit};
use super::vars::VarKind;
use super::{FitError, FitOptions, Series, StageFit};
use crate::signal::project_drift;

/// A fitted stage with its optimum, for analyses that extend it (the gap diagnosis).
#[derive(Clone)]
pub struct FittedStage<'a> {
    pub stage: Stage<'a>,
    /// The optimum in the stage's scaled variables.
    pub u: Vec<f64>,
    /// Training window (inclusive sample indices) and the samples the cost uses.
    pub first: usize,
    pub last: usize,
    pub keep: Vec<usize>,
}

/// A solved stage: the report, the variables' values and the optimizer's result.
pub struct Solved {
    pub fit: StageFit,
    pub values: Vec<f64>,
    pub lm: LmResult,
    /// Covariance of the scaled variables from the noise on the prescribed inputs.
    pub noise_cov: Option<DMatrix<f64>>,
    pub keep: Vec<usize>,
}

/// Fit a stage on the training indices `train` (skipping `burn` samples at its start), then
/// report the train and holdout fits.
pub fn fit_stage(
    stage: &Stage,
    train: (usize, usize),
    hold: Option<(usize, usize)>,
    burn: usize,
    opts: &FitOptions,
) -> Result<Solved, FitError> {
    let clock = Instant::now();
    let keep: Vec<usize> = ((train.0 + burn).min(train.1)..=train.1).collect();
    let mut last_err = None;
    let mut eval = |u: &[f64]| match stage.residuals(u, train.0, train.1, &keep) {
        Ok(v) => Some(v),
        Err(e) => {
            last_err = Some(e);
            None
        }
    };
    let u0 = vec![0.0; stage.vars.len()];
    let mut resid = |u: &[f64]| stage.trial_residuals(u, train.0, train.1, &keep).ok();
    // trial points by their residuals alone, the sensitivities only at accepted ones
    let res = lm::minimize_split(&mut eval, Some(&mut resid), &u0, &opts.lm)
        .ok_or_else(|| last_err.unwrap_or(FitError::Start(stage.name.into())))?;
    let noise_cov = stage.input_noise_cov(
        &res.x,
        train.0,
        train.1,
        &keep,
        &res.jacobian,
        opts.input_noise_draws,
        0x5eed,
    )?;
    let stats = stats(stage, &res, noise_cov.as_ref());
    let (fits, series) = evaluate(stage, &res.x, train, hold, burn, keep.len())?;
    let fit = StageFit {
        stage: stage.name.into(),
        stats,
        fits,
        iterations: res.iterations,
        evaluations: res.evaluations,
        converged: res.converged,
        seconds: clock.elapsed().as_secs_f64(),
        series,
    };
    Ok(Solved {
        fit,
        values: stage.values(&res.x),
        lm: res,
        noise_cov,
        keep,
    })
}

/// The statistics of a stage's optimum with a further covariance `extra` of the scaled
/// variables (input noise, or uncertainty carried in from another stage).
pub fn stats(stage: &Stage, res: &LmResult, extra: Option<&DMatrix<f64>>) -> report::FitStats {
    let names: Vec<(String, bool)> = stage
        .vars
        .iter()
        .map(|v| (v.name.clone(), matches!(v.kind, VarKind::Param(_))))
        .collect();
    let init: Vec<f64> = stage.vars.iter().map(|v| v.initial).collect();
    let scale: Vec<f64> = stage.vars.iter().map(|v| v.scale).collect();
    report::stats_full(
        &names,
        &init,
        &scale,
        &res.x,
        &res.residuals,
        &res.jacobian,
        stage.drift * stage.outputs.len(),
        extra,
    )
}

/// Fit percentages on the training and held-out blocks, and the series for plots (one run
/// from the training start when the holdout follows it).
fn evaluate(
    stage: &Stage,
    u: &[f64],
    train: (usize, usize),
    hold: Option<(usize, usize)>,
    burn: usize,
    kept: usize,
) -> Result<(Vec<ChannelFit>, Vec<Series>), FitError> {
    let keep: Vec<usize> = ((train.0 + burn).min(train.1)..=train.1).collect();
    let end = hold.map(|h| h.1.max(train.1)).unwrap_or(train.1);
    let whole = hold.is_none_or(|h| h.0 >= train.0);
    let run = stage.run(u, train.0, if whole { end } else { train.1 }, false)?;
    let mut fits = Vec::new();
    fits.extend(block_fits(stage, "train", &keep, &run, kept));
    if let Some(h) = hold {
        if whole {
            let idx: Vec<usize> = (h.0.max(train.0 + burn)..=h.1).collect();
            fits.extend(block_fits(stage, "holdout", &idx, &run, kept));
        } else {
            let idx: Vec<usize> = ((h.0 + burn).min(h.1)..=h.1).collect();
            let hrun = stage.run(u, h.0, h.1, false)?;
            fits.extend(block_fits(stage, "holdout", &idx, &hrun, kept));
        }
    }
    let series = stage
        .outputs
        .iter()
        .enumerate()
        .map(|(o, out)| {
            let range = run.first..run.first + run.yhat[o].len();
            Series {
                channel: out.channel.clone(),
                t: range
                    .clone()
                    .map(|i| stage.t0 + i as f64 * stage.dt)
                    .collect(),
                measured: range.map(|i| out.data[i]).collect(),
                model: run.yhat[o].clone(),
            }
        })
        .collect();
    Ok((fits, series))
}

/// Each output's fit on the samples `idx` of a run.
fn block_fits(
    stage: &Stage,
    block: &str,
    idx: &[usize],
    run: &super::driven::StageRun,
    kept: usize,
) -> Vec<ChannelFit> {
    let mut fits = Vec::new();
    for (o, out) in stage.outputs.iter().enumerate() {
        let y: Vec<f64> = idx.iter().map(|&i| out.data[i]).collect();
        let mut yh: Vec<f64> = idx.iter().map(|&i| run.yhat[o][i - run.first]).collect();
        let raw = fit_percent(&y, &yh);
        if stage.drift > 0 {
            // the sub-cycle drift the fit ignores (the wander driven by input noise) is
            // removed from the model error on this block too, in the same band
            let m = (stage.drift as f64 * y.len() as f64 / kept as f64).round() as usize;
            let mut e: Vec<f64> = y.iter().zip(&yh).map(|(a, b)| b - a).collect();
            if block != "train" {
                // the training block's mean is carried by the fitted offsets
                let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
                e.iter_mut().for_each(|v| *v -= mean);
            }
            project_drift(&mut e, m);
            yh = y.iter().zip(&e).map(|(a, b)| a + b).collect();
        }
        let rms = (y
            .iter()
            .zip(&yh)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            / y.len().max(1) as f64)
            .sqrt();
        fits.push(ChannelFit {
            channel: out.channel.clone(),
            block: block.to_string(),
            fit_percent: fit_percent(&y, &yh),
            fit_percent_raw: raw,
            rms,
            samples: y.len(),
        });
    }
    fits
}
