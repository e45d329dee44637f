//! Identification from measured data, the seed's two stages (Figures 3-5):
//! stage 1 fits the mechanics driven by the measured pressure, stage 2 the gas model driven by
//! the measured displacements ([`driven`]), each by Levenberg-Marquardt ([`lm`]) on forward
//! sensitivities ([`sensitivity`]), with a statistical report ([`report`]).
//!
//! Then, optionally, a multiple-shooting refinement over short free-running segments
//! ([`multiple_shooting`]) and a free-run validation from the measured initial state
//! ([`free_run`]), since a self-excited oscillator drifts in phase.

pub mod driven;
pub mod free_run;
pub mod lm;
pub mod multiple_shooting;
pub mod prior;
pub mod report;
pub mod sensitivity;

use std::time::Instant;

use serde::Serialize;
use stirling_dsl::{Model, StateKind};

use crate::data::{cycle_mean, Measured};
use crate::sim::SimOptions;
use driven::{
    cold_weight, noise_sigma, pressure_states, savitzky_golay, split_states, static_shift, Output,
    Stage, Var, VarKind,
};
use report::{fit_percent, ChannelFit, FitStats};
use sensitivity::{Given, Signal};

/// Why a fit failed.
#[derive(Clone, Debug, thiserror::Error)]
pub enum FitError {
    #[error("{0}")]
    Bad(String),
    #[error("{0}: simulation failed: {1}")]
    Sim(String, String),
    #[error("{0}: the optimizer could not evaluate the starting point")]
    Start(String),
}

/// Options of the two-stage fit.
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Free parameters (split by stage automatically); `None`: the defaults
    /// (stage 1 `kd, kp, bd, bp`; stage 2 `hh, hk, Rf` where the model uses them).
    pub free: Option<Vec<String>>,
    /// Training block `[a, b]` (s); default: the first 70 % of the record.
    pub train: Option<(f64, f64)>,
    /// Held-out block; default: the rest of the record.
    pub holdout: Option<(f64, f64)>,
    /// Stage-2 samples skipped at the window start while the gas forgets its initial state (s).
    pub burn_in: f64,
    /// Half-width of the smoothing window for prescribed inputs (s).
    pub smooth: f64,
    pub lm: lm::LmOptions,
    pub sim: SimOptions,
    /// Run stage 1 / stage 2.
    pub stage1: bool,
    pub stage2: bool,
    /// Stage 1: sub-cycle drift band projected out of the residuals, as a fraction of the
    /// cycle frequency (see [`driven::Stage::drift`]; 0: none).
    pub drift_cut: f64,
    /// Monte Carlo draws for the input-noise (errors-in-variables) part of the parameter
    /// covariance (0: skip it; the intervals then miss that part).
    pub input_noise_draws: usize,
    /// Log-normal prior on the free model parameters around their starting values, as a log
    /// standard deviation (see [`prior`]; `None`: plain least squares).
    pub prior: Option<f64>,
    /// Free-run validation after the stages (on the held-out block, else the training block).
    pub free_run: Option<free_run::FreeRunOptions>,
    /// Multiple-shooting refinement of the free parameters over the training block (off by
    /// default: it costs several times the two stages).
    pub multiple_shooting: Option<multiple_shooting::MsOptions>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            free: None,
            train: None,
            holdout: None,
            // the gas's initial temperatures and mass shares are guesses; their transient
            // lasts several thermal time constants (0.03 s left hh/hk 10 % off on nsection n = 2)
            burn_in: 0.2,
            smooth: 0.006,
            lm: lm::LmOptions {
                max_iter: 30,
                ftol: 1e-8,
                xtol: 1e-7,
                lambda0: 1e-3,
                max_step: f64::INFINITY,
            },
            sim: SimOptions {
                rtol: 1e-7,
                atol: 1e-7,
                ..Default::default()
            },
            stage1: true,
            stage2: true,
            drift_cut: 0.5,
            input_noise_draws: 40,
            prior: None,
            free_run: Some(free_run::FreeRunOptions::default()),
            multiple_shooting: None,
        }
    }
}

/// Measured and simulated output on the record, for plots.
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    pub channel: String,
    pub t: Vec<f64>,
    pub measured: Vec<f64>,
    pub model: Vec<f64>,
}

/// One stage's result.
#[derive(Clone, Debug, Serialize)]
pub struct StageFit {
    pub stage: String,
    pub stats: FitStats,
    pub fits: Vec<ChannelFit>,
    pub iterations: usize,
    pub evaluations: usize,
    pub converged: bool,
    pub seconds: f64,
    #[serde(skip)]
    pub series: Vec<Series>,
}

impl StageFit {
    /// Fit percentage of a channel on a block (`train` or `holdout`).
    pub fn fit_percent(&self, channel: &str, block: &str) -> Option<f64> {
        self.fits
            .iter()
            .find(|f| f.channel == channel && f.block == block)
            .map(|f| f.fit_percent)
    }
    /// The estimate of a quantity by name.
    pub fn estimate(&self, name: &str) -> Option<&report::Estimate> {
        self.stats.estimates.iter().find(|e| e.name == name)
    }
}

/// The identification result.
#[derive(Clone, Debug, Serialize)]
pub struct Identification {
    pub model: String,
    pub n: usize,
    /// All parameters after the fit.
    pub params: Vec<(String, f64)>,
    pub stage1: Option<StageFit>,
    pub stage2: Option<StageFit>,
    pub train: (f64, f64),
    pub holdout: Option<(f64, f64)>,
    pub seconds: f64,
    /// Sensor offsets after the fit (position offsets as seen by the free model, i.e. with
    /// the stage-2 pressure-offset correction applied).
    pub offsets: free_run::SensorOffsets,
    pub multiple_shooting: Option<multiple_shooting::MultipleShooting>,
    pub free_run: Option<free_run::FreeRun>,
    /// Why an optional step (refinement, free run) did not run.
    pub notes: Vec<String>,
}

/// Split the free parameters by the rows they enter: body rows -> stage 1, gas rows -> stage 2.
pub fn classify(
    model: &dyn Model,
    p: &[f64],
    names: &[String],
) -> Result<(Vec<usize>, Vec<usize>), FitError> {
    let n = model.n_states();
    let mut x = vec![0.0; n];
    model.equilibrium_guess(p, &mut x);
    for (i, s) in model.states().iter().enumerate() {
        match s.kind {
            StateKind::Position(k) => x[i] = 1e-3 * (1.0 + k as f64),
            StateKind::Velocity(k) => x[i] = 0.1 * (1.0 + 0.5 * k as f64),
            StateKind::Pressure(k) => x[i] *= 1.0 + 0.01 * (1.0 + k as f64),
            StateKind::Mass(_) => {}
        }
    }
    let jp = model.param_jacobian_dense(p, &x, 0.0);
    let st = model.states();
    let (mut mech, mut gas) = (Vec::new(), Vec::new());
    for name in names {
        let j = model.param_index(name).ok_or_else(|| {
            FitError::Bad(format!(
                "unknown parameter `{name}` of model `{}`: see `stirling info {}`",
                model.name(),
                model.name()
            ))
        })?;
        let col = &jp[j * n..(j + 1) * n];
        let body = st
            .iter()
            .zip(col)
            .any(|(s, v)| matches!(s.kind, StateKind::Velocity(_)) && *v != 0.0);
        let g = st.iter().zip(col).any(|(s, v)| {
            matches!(s.kind, StateKind::Pressure(_) | StateKind::Mass(_)) && *v != 0.0
        });
        if !body && !g {
            return Err(FitError::Bad(format!(
                "parameter `{name}` does not enter the equations of `{}`: it cannot be identified",
                model.name()
            )));
        }
        if body {
            mech.push(j);
        }
        if g {
            gas.push(j);
        }
    }
    Ok((mech, gas))
}

/// Default free parameters that the model uses.
pub fn default_free(model: &dyn Model, p: &[f64]) -> Vec<String> {
    ["kd", "kp", "bd", "bp", "hh", "hk", "Rf"]
        .iter()
        .map(|s| s.to_string())
        .filter(|s| classify(model, p, std::slice::from_ref(s)).is_ok())
        .collect()
}

fn uniform(data: &Measured) -> Result<(f64, f64), FitError> {
    if data.t.len() < 20 {
        return Err(FitError::Bad(format!(
            "{}: {} samples are too few to fit",
            data.source,
            data.t.len()
        )));
    }
    let dt = data.dt();
    for k in 1..data.t.len() {
        let d = data.t[k] - data.t[k - 1];
        if (d - dt).abs() > 1e-3 * dt {
            return Err(FitError::Bad(format!(
                "{}: the fit needs uniform sampling; the interval at t = {} is {d}, the mean {dt}",
                data.source, data.t[k]
            )));
        }
    }
    Ok((data.t[0], dt))
}

fn signal(t0: f64, dt: f64, y: &[f64], h: usize) -> Signal {
    let (val, der) = savitzky_golay(y, dt, h, 4);
    Signal { t0, dt, val, der }
}

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

/// The fit variables of the model parameters `free` (indices), scaled by their values.
fn param_vars(model: &dyn Model, p: &[f64], free: &[usize], prior: Option<f64>) -> Vec<Var> {
    free.iter()
        .map(|&j| Var {
            name: model.params()[j].name.into(),
            initial: p[j],
            scale: p[j].abs().max(1e-12),
            kind: VarKind::Param(j),
            prior,
        })
        .collect()
}

/// Fit a stage on the training indices, then report train and holdout fits.
fn fit_stage(
    stage: &Stage,
    train: (usize, usize),
    hold: Option<(usize, usize)>,
    burn: usize,
    opts: &FitOptions,
) -> Result<(StageFit, Vec<f64>, Vec<f64>), FitError> {
    let lm_opts = &opts.lm;
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
    let res = lm::minimize(&mut eval, &u0, lm_opts).ok_or_else(|| {
        last_err
            .clone()
            .unwrap_or(FitError::Start(stage.name.into()))
    })?;
    let names: Vec<(String, bool)> = stage
        .vars
        .iter()
        .map(|v| (v.name.clone(), matches!(v.kind, VarKind::Param(_))))
        .collect();
    let init: Vec<f64> = stage.vars.iter().map(|v| v.initial).collect();
    let scale: Vec<f64> = stage.vars.iter().map(|v| v.scale).collect();
    let extra = stage.input_noise_cov(
        &res.x,
        train.0,
        train.1,
        &keep,
        &res.jacobian,
        opts.input_noise_draws,
        0x5eed,
    )?;
    let st = report::stats_full(
        &names,
        &init,
        &scale,
        &res.x,
        &res.residuals,
        &res.jacobian,
        stage.drift * stage.outputs.len(),
        extra.as_ref(),
    );
    // evaluation over train and holdout (one run from the training start when possible)
    let end = hold.map(|h| h.1.max(train.1)).unwrap_or(train.1);
    let mut fits = Vec::new();
    let mut series = Vec::new();
    let whole = hold.is_none_or(|h| h.0 >= train.0);
    let run = stage.run(&res.x, train.0, if whole { end } else { train.1 }, false)?;
    let mut blocks = vec![("train", keep.clone(), &run)];
    let hrun;
    if let Some(h) = hold {
        let idx: Vec<usize> = if whole {
            (h.0.max(train.0 + burn)..=h.1).collect()
        } else {
            ((h.0 + burn).min(h.1)..=h.1).collect()
        };
        if !whole {
            hrun = stage.run(&res.x, h.0, h.1, false)?;
            blocks.push(("holdout", idx, &hrun));
        } else {
            blocks.push(("holdout", idx, &run));
        }
    }
    for (block, idx, r) in &blocks {
        for (o, out) in stage.outputs.iter().enumerate() {
            let y: Vec<f64> = idx.iter().map(|&i| out.data[i]).collect();
            let mut yh: Vec<f64> = idx.iter().map(|&i| r.yhat[o][i - r.first]).collect();
            let raw = fit_percent(&y, &yh);
            if stage.drift > 0 {
                // the sub-cycle drift the fit ignores (the wander driven by input noise) is
                // removed from the model error on this block too, in the same band
                let m = (stage.drift as f64 * y.len() as f64 / keep.len() as f64).round() as usize;
                let mut e: Vec<f64> = y.iter().zip(&yh).map(|(a, b)| b - a).collect();
                if *block != "train" {
                    // the training block's mean is carried by the fitted offsets
                    let mean = e.iter().sum::<f64>() / e.len().max(1) as f64;
                    e.iter_mut().for_each(|v| *v -= mean);
                }
                driven::project_drift(&mut e, m);
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
    }
    for (o, out) in stage.outputs.iter().enumerate() {
        let t: Vec<f64> = (run.first..run.first + run.yhat[o].len())
            .map(|i| stage.t0 + i as f64 * stage.dt)
            .collect();
        let measured = (run.first..run.first + run.yhat[o].len())
            .map(|i| out.data[i])
            .collect();
        series.push(Series {
            channel: out.channel.clone(),
            t,
            measured,
            model: run.yhat[o].clone(),
        });
    }
    let values = stage.values(&res.x);
    Ok((
        StageFit {
            stage: stage.name.into(),
            stats: st,
            fits,
            iterations: res.iterations,
            evaluations: res.evaluations,
            converged: res.converged,
            seconds: clock.elapsed().as_secs_f64(),
            series,
        },
        values,
        res.x,
    ))
}

/// The two-stage identification of `model` (starting from `p0`) on a measured record.
pub fn identify(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &FitOptions,
) -> Result<Identification, FitError> {
    identify_stages(model, p0, data, opts).map(|(id, _)| id)
}

/// [`identify`], also returning the fitted stages (stage 1, then stage 2, those that ran).
pub fn identify_stages<'a>(
    model: &'a dyn Model,
    p0: &[f64],
    data: &Measured,
    opts: &FitOptions,
) -> Result<(Identification, Vec<FittedStage<'a>>), FitError> {
    let mut fitted = Vec::new();
    let clock = Instant::now();
    let (t0, dt) = uniform(data)?;
    let nt = data.t.len();
    let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(nt - 1);
    let t_last = data.t[nt - 1];
    let train = opts.train.unwrap_or((t0, t0 + 0.7 * (t_last - t0)));
    let holdout = match (opts.holdout, opts.train) {
        (Some(h), _) => Some(h),
        (None, None) => Some((train.1, t_last)),
        (None, Some(_)) => None,
    };
    let tr = (idx(train.0), idx(train.1));
    let ho = holdout.map(|h| (idx(h.0), idx(h.1)));
    if tr.1 < tr.0 + 10 {
        return Err(FitError::Bad(format!(
            "the training block {}:{} holds fewer than 10 samples",
            train.0, train.1
        )));
    }
    let free = opts.free.clone().unwrap_or_else(|| default_free(model, p0));
    let mut p = p0.to_vec();
    let (mech, gas) = classify(model, &p, &free)?;
    let h = ((opts.smooth / dt).round() as usize).max(3);
    let (bodies, gas_states) = split_states(model);
    let ps = pressure_states(model);
    let have_hot = data.p_hot.is_some() && ps.len() > 1;
    let mut eq = vec![0.0; model.n_states()];
    model.equilibrium_guess(&p, &mut eq);
    let pmean = ps.first().map(|&i| eq[i]).unwrap_or(0.0);
    let pos_states: Vec<usize> = bodies
        .iter()
        .copied()
        .filter(|&i| matches!(model.states()[i].kind, StateKind::Position(_)))
        .collect();
    let (x_meas, y_meas) = (data.x.as_ref(), data.y.as_ref());
    let mut x_off = [
        x_meas.map(|v| cycle_mean(v)).unwrap_or(0.0),
        y_meas.map(|v| cycle_mean(v)).unwrap_or(0.0),
    ];
    let mut stage1 = None;
    let sim = opts.sim;

    // pressure-offset guesses: the whole-cycle mean minus the charge pressure (refined in stage 2)
    let p_off0 = data
        .p
        .as_ref()
        .map(|v| cycle_mean(v) - pmean)
        .unwrap_or(0.0);
    let ph_off0 = data
        .p_hot
        .as_ref()
        .map(|v| cycle_mean(v) - pmean)
        .unwrap_or(0.0);
    let mut offsets = free_run::SensorOffsets {
        x: x_off[0],
        y: x_off[1],
        p: p_off0,
        p_hot: have_hot.then_some(ph_off0),
    };
    let sig_p = data.p.as_ref().map(|v| signal(t0, dt, v, (h / 2).max(3)));
    let sig_ph = data
        .p_hot
        .as_ref()
        .map(|v| signal(t0, dt, v, (h / 2).max(3)));

    if opts.stage1 && !mech.is_empty() {
        let (Some(xm), Some(ym), Some(sp)) = (x_meas, y_meas, sig_p.as_ref()) else {
            return Err(FitError::Bad(format!(
                "{}: stage 1 (mechanics) needs the columns p, x and y",
                data.source
            )));
        };
        if pos_states.len() != 2 {
            return Err(FitError::Bad(
                "stage 1 expects two bodies (displacer x, piston y)".into(),
            ));
        }
        let mut signals = vec![sp.clone()];
        if have_hot {
            signals.push(sig_ph.clone().expect("have_hot"));
        }
        let given: Vec<Given> = ps
            .iter()
            .enumerate()
            .map(|(i, &s)| {
                let wc = cold_weight(i, ps.len(), have_hot);
                let mut terms = vec![(0, wc, false)];
                if have_hot {
                    terms.push((1, 1.0 - wc, false));
                }
                Given {
                    state: s,
                    terms,
                    constant: -wc * p_off0 - if have_hot { (1.0 - wc) * ph_off0 } else { 0.0 },
                }
            })
            .collect();
        let sx = signal(t0, dt, xm, h);
        let sy = signal(t0, dt, ym, h);
        let ta = tr.0;
        let z0 = vec![
            sx.val[ta] - x_off[0],
            sx.der[ta],
            sy.val[ta] - x_off[1],
            sy.der[ta],
        ];
        let mut vars = param_vars(model, &p, &mech, opts.prior);
        let names = ["x(0)", "v(0)", "y(0)", "w(0)"];
        for (k, nm) in names.iter().enumerate() {
            vars.push(Var {
                name: nm.to_string(),
                initial: z0[k],
                scale: if k % 2 == 0 { 1e-3 } else { 0.05 },
                kind: VarKind::Initial(k),
                prior: None,
            });
        }
        vars.push(Var {
            name: "x_offset".into(),
            initial: x_off[0],
            scale: 1e-3,
            kind: VarKind::Offset { out: 0, du: vec![] },
            prior: None,
        });
        vars.push(Var {
            name: "y_offset".into(),
            initial: x_off[1],
            scale: 1e-3,
            kind: VarKind::Offset { out: 1, du: vec![] },
            prior: None,
        });
        let outputs = vec![
            Output {
                channel: "x".into(),
                pos: 0,
                data: xm.clone(),
                sigma: noise_sigma(xm).max(1e-9),
            },
            Output {
                channel: "y".into(),
                pos: 2,
                data: ym.clone(),
                sigma: noise_sigma(ym).max(1e-9),
            },
        ];
        let f0 = driven::cycle_frequency(&ym[tr.0..=tr.1], dt)
            .or_else(|| driven::cycle_frequency(&xm[tr.0..=tr.1], dt))
            .unwrap_or(0.0);
        let drift = driven::drift_count(tr.1 - tr.0 + 1, dt, opts.drift_cut * f0);
        if std::env::var_os("STIRLING_FIT_DEBUG").is_some() {
            eprintln!("stage 1: cycle frequency {f0:.3} Hz, {drift} drift cosines per output");
        }
        let stage = Stage {
            drift,
            input_noise: std::iter::once((
                0,
                noise_sigma(data.p.as_ref().expect("checked")),
                (h / 2).max(3),
            ))
            .chain(
                data.p_hot
                    .as_ref()
                    .filter(|_| have_hot)
                    .map(|v| (1, noise_sigma(v), (h / 2).max(3))),
            )
            .collect(),
            name: "stage 1 (mechanics driven by measured pressure)",
            model,
            p: p.clone(),
            base: eq.clone(),
            free: bodies.clone(),
            given,
            signals,
            z0,
            vars,
            outputs,
            t0,
            dt,
            sim,
        };
        let (fit, values, u) = fit_stage(&stage, tr, ho, 0, opts)?;
        for (v, val) in stage.vars.iter().zip(&values) {
            match v.kind {
                VarKind::Param(j) => p[j] = *val,
                VarKind::Offset { out, .. } => x_off[out] = *val,
                _ => {}
            }
        }
        stage1 = Some(fit);
        fitted.push(FittedStage {
            stage,
            u,
            first: tr.0,
            last: tr.1,
            keep: (tr.0..=tr.1).collect(),
        });
    }

    let mut stage2 = None;
    if opts.stage2 && !gas.is_empty() {
        let (Some(xm), Some(ym), Some(sp)) = (x_meas, y_meas, sig_p.as_ref()) else {
            return Err(FitError::Bad(format!(
                "{}: stage 2 (gas) needs the columns p, x and y",
                data.source
            )));
        };
        model.equilibrium_guess(&p, &mut eq);
        let shift = static_shift(model, &p, have_hot)?;
        let sx = signal(t0, dt, xm, h);
        let sy = signal(t0, dt, ym, h);
        let signals = vec![sx.clone(), sy.clone()];
        let vel_states: Vec<usize> = bodies
            .iter()
            .copied()
            .filter(|&i| matches!(model.states()[i].kind, StateKind::Velocity(_)))
            .collect();
        // stage 1 ran with the pressure offsets (p_off0, ph_off0); an offset `off` moves the
        // true positions by -dq (off - off0) relative to the stage-1 offsets
        let used = [
            shift[0][0] * p_off0 + shift[1][0] * ph_off0,
            shift[0][1] * p_off0 + shift[1][1] * ph_off0,
        ];
        let given = vec![
            Given {
                state: pos_states[0],
                terms: vec![(0, 1.0, false)],
                constant: -x_off[0] + used[0],
            },
            Given {
                state: vel_states[0],
                terms: vec![(0, 1.0, true)],
                constant: 0.0,
            },
            Given {
                state: pos_states[1],
                terms: vec![(1, 1.0, false)],
                constant: -x_off[1] + used[1],
            },
            Given {
                state: vel_states[1],
                terms: vec![(1, 1.0, true)],
                constant: 0.0,
            },
        ];
        let du = |ch: usize| vec![-shift[ch][0], 0.0, -shift[ch][1], 0.0];
        let pm = data.p.as_ref().expect("checked");
        let cold_pos = gas_states
            .iter()
            .position(|&i| i == *ps.last().expect("CVs"))
            .expect("pressure is a gas state");
        let hot_pos = gas_states
            .iter()
            .position(|&i| i == ps[0])
            .expect("pressure is a gas state");
        let mut vars = param_vars(model, &p, &gas, opts.prior);
        vars.push(Var {
            name: "p_offset".into(),
            initial: p_off0,
            scale: 100.0,
            kind: VarKind::Offset { out: 0, du: du(0) },
            prior: None,
        });
        let mut outputs = vec![Output {
            channel: "p".into(),
            pos: cold_pos,
            data: pm.clone(),
            sigma: noise_sigma(pm).max(1e-6 * pmean),
        }];
        if have_hot {
            let ph = data.p_hot.as_ref().expect("have_hot");
            vars.push(Var {
                name: "p_hot_offset".into(),
                initial: ph_off0,
                scale: 100.0,
                kind: VarKind::Offset { out: 1, du: du(1) },
                prior: None,
            });
            outputs.push(Output {
                channel: "p_hot".into(),
                pos: hot_pos,
                data: ph.clone(),
                sigma: noise_sigma(ph).max(1e-6 * pmean),
            });
        }
        // initial gas state at the window start: measured pressures, masses sharing the
        // model's inventory in proportion to P V / T_rest
        let mut x_start = eq.clone();
        let ta = tr.0;
        x_start[pos_states[0]] = sx.val[ta] - x_off[0];
        x_start[vel_states[0]] = sx.der[ta];
        x_start[pos_states[1]] = sy.val[ta] - x_off[1];
        x_start[vel_states[1]] = sy.der[ta];
        let ncv = ps.len();
        let mut t_rest = vec![0.0; ncv];
        model.temperatures(&p, &eq, &mut t_rest);
        for (i, &s) in ps.iter().enumerate() {
            let wc = cold_weight(i, ncv, have_hot);
            let hot = sig_ph
                .as_ref()
                .filter(|_| have_hot)
                .map(|s| s.val[ta] - ph_off0)
                .unwrap_or(0.0);
            x_start[s] = wc * (sp.val[ta] - p_off0) + (1.0 - wc) * hot;
        }
        let masses: Vec<usize> = model
            .states()
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.kind, StateKind::Mass(_)))
            .map(|(i, _)| i)
            .collect();
        if !masses.is_empty() {
            let nv = model.vessel_names().len();
            let (mut pr, mut vol) = (vec![0.0; nv], vec![0.0; nv]);
            model.pv(&p, &x_start, &mut pr, &mut vol);
            let total: f64 = masses.iter().map(|&i| eq[i]).sum();
            let share: Vec<f64> = (0..ncv)
                .map(|i| x_start[ps[i]] * vol[i] / t_rest[i])
                .collect();
            let ssum: f64 = share.iter().sum();
            for (k, &mi) in masses.iter().enumerate() {
                x_start[mi] = total * share[k] / ssum;
            }
        }
        let z0: Vec<f64> = gas_states.iter().map(|&i| x_start[i]).collect();
        let burn = ((opts.burn_in / dt).round() as usize).min(tr.1 - tr.0 - 5);
        let stage = Stage {
            drift: 0,
            input_noise: vec![(0, noise_sigma(xm), h), (1, noise_sigma(ym), h)],
            name: "stage 2 (gas driven by measured displacements)",
            model,
            p: p.clone(),
            base: eq.clone(),
            free: gas_states.clone(),
            given,
            signals,
            z0,
            vars,
            outputs,
            t0,
            dt,
            sim,
        };
        let (fit, values, u) = fit_stage(&stage, tr, ho, burn, opts)?;
        let (mut p_off, mut ph_off) = (p_off0, ph_off0);
        for (v, val) in stage.vars.iter().zip(&values) {
            match v.kind {
                VarKind::Param(j) => p[j] = *val,
                VarKind::Offset { out: 0, .. } => p_off = *val,
                VarKind::Offset { out: 1, .. } => ph_off = *val,
                _ => {}
            }
        }
        // the positions stage 2 prescribed: measured - x_off + used - shift (offsets)
        for k in 0..2 {
            x_off[k] += shift[0][k] * p_off + shift[1][k] * ph_off - used[k];
        }
        offsets.p = p_off;
        if have_hot {
            offsets.p_hot = Some(ph_off);
        }
        stage2 = Some(fit);
        fitted.push(FittedStage {
            stage,
            u,
            first: tr.0,
            last: tr.1,
            keep: ((tr.0 + burn).min(tr.1)..=tr.1).collect(),
        });
    }
    offsets.x = x_off[0];
    offsets.y = x_off[1];
    let mut notes = Vec::new();
    let mut ms = None;
    if let Some(mo) = &opts.multiple_shooting {
        let mut idx_free: Vec<usize> = mech.clone();
        idx_free.extend(gas.iter().filter(|j| !mech.contains(j)));
        match multiple_shooting::multiple_shooting(model, &p, &idx_free, data, &offsets, train, mo)
        {
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
        let block = holdout.unwrap_or(train);
        match free_run::free_run(model, &p, data, &offsets, block, fo) {
            Ok(r) => fr = Some(r),
            Err(e) => notes.push(format!("free run: {e}")),
        }
    }
    let id = Identification {
        model: model.name().into(),
        n: model.n(),
        params: model
            .params()
            .iter()
            .zip(&p)
            .map(|(i, v)| (i.name.to_string(), *v))
            .collect(),
        stage1,
        stage2,
        train,
        holdout,
        seconds: clock.elapsed().as_secs_f64(),
        offsets,
        multiple_shooting: ms,
        free_run: fr,
        notes,
    };
    Ok((id, fitted))
}
