//! Stage 1 of a kinematic engine: the flywheel's friction and load from its torque balance.
//!
//! The angle is measured, so its acceleration is too (the second derivative of the smoothed
//! angle, Savitzky-Golay of degree 4 twice, the half-width the record's smoothing). The gas
//! that pushes the cranks is the fitted stage 2's, driven by that angle: its pressures act on
//! the faces, through the cranks' derivatives, as a torque on the wheel. What is left of the
//! model's `omega' = (T_gas - T_friction - T_load) / J` at each sample is a function of the
//! flywheel's parameters (`cf`, `Tc`, `Tl`, ... : whichever free parameters act on no row of
//! the driven gas), fitted by Gauss-Newton on the measured acceleration (linear in the
//! friction torques: one step, a few for an inertia or a smoothing scale). No stage of the gas
//! is rerun, so the gas's estimates are those of stage 2.
//!
//! The intervals come from the angle's noise carried through the smoothing, the two
//! derivatives and the estimator by Monte Carlo (`angle_noise.rs`), scaled up when the
//! model misses the acceleration by more than the noise does, plus the gas's own uncertainty
//! (`gas_spread.rs`). At a steady speed the Coulomb torque and a load are one
//! torque (`tanh(omega / w_eps) = 1` at every sample) and the viscous torque `cf omega` nearly
//! one with them: their correlation is reported as a warning and their intervals are as wide
//! as that makes them; a record that speeds up or slows down separates them.

use std::time::Instant;

use nalgebra::{DMatrix, DVector};
use stirling_dsl::{JacSink, Model};

use super::angle::Angle;
use super::angle_noise::AngleNoise;
use super::gas_spread::Balance;
use crate::fit::record::Record;
use crate::fit::report::{ChannelFit, Estimate, FitStats};
use crate::fit::stage_fit::FittedStage;
use crate::fit::{FitError, StageFit};
use crate::signal::{noise_sigma, savitzky_golay};

/// Gauss-Newton iterations at most (the friction torques are linear: the first step lands).
const MAX_ITER: usize = 8;
/// A step smaller than this (relative to each parameter's scale) ends the iterations.
const STEP_TOL: f64 = 1e-10;
/// Correlation above which a pair of estimates is named in the warnings.
const CORRELATED: f64 = 0.95;

/// The stage's name in reports.
pub const NAME: &str =
    "stage 1 (the flywheel's torque balance: the measured angle, the fitted gas)";

/// What the torque balance sees at each sample: the model's state and the measured
/// acceleration.
pub(super) struct Samples {
    /// Full model states (gas from stage 2, angle and speed from the record).
    pub x: Vec<Vec<f64>>,
    /// Measured angular acceleration (rad/s^2).
    pub acc: Vec<f64>,
    /// Times (s).
    pub t: Vec<f64>,
}

/// Fit the flywheel's parameters `mech` (indices into `p`) on the training block after the
/// burn-in, the gas as fitted (`gas`, its statistics `gas_stats`, `p` with its estimates);
/// `p` gets the fitted values.
pub fn fit(
    model: &dyn Model,
    p: &mut [f64],
    (gas, gas_stats, burn): (&FittedStage, &FitStats, usize),
    angle: &Angle,
    rec: &Record,
    mech: &[usize],
) -> Result<StageFit, FitError> {
    let clock = Instant::now();
    let last = rec.ho.map_or(rec.tr.1, |h| h.1);
    let states = gas.stage.full_states(&gas.u, rec.tr.0, last)?;
    let (_, speed) = savitzky_golay(&angle.data, rec.dt, rec.h, 4);
    let (_, acc) = savitzky_golay(&speed, rec.dt, rec.h, 4);
    let block = |a: usize, b: usize| Samples {
        x: states[a - rec.tr.0..=b - rec.tr.0].to_vec(),
        acc: acc[a..=b].to_vec(),
        t: (a..=b).map(|k| rec.t0 + k as f64 * rec.dt).collect(),
    };
    let train = block(rec.tr.0 + burn, rec.tr.1);
    let p0: Vec<f64> = mech.iter().map(|&j| p[j]).collect();
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ITER {
        iterations += 1;
        let (r, jm) = rows(model, p, angle.speed, &train, mech);
        let step = least_squares(&jm, &r).ok_or_else(|| singular(model, mech))?;
        let mut small = true;
        for (k, &j) in mech.iter().enumerate() {
            small &= step[k].abs() <= STEP_TOL * p[j].abs().max(f64::MIN_POSITIVE);
            p[j] += step[k];
        }
        if small {
            converged = true;
            break;
        }
    }
    let (r, jm) = rows(model, p, angle.speed, &train, mech);
    let noise = AngleNoise {
        sd: noise_sigma(&angle.data[rec.tr.0..=rec.tr.1]),
        len: angle.data.len(),
        first: rec.tr.0 + burn,
    };
    let balance = Balance {
        first: rec.tr.0 + burn,
        last: rec.tr.1,
        acc: &acc,
        t0: rec.t0,
        dt: rec.dt,
        speed: angle.speed,
        mech,
    };
    let (gas_cov, skipped) = balance.gas_cov(model, p, gas, gas_stats)?;
    let mut stats = stats(model, (p, &p0), mech, (&r, &jm), (&noise, rec), &gas_cov)
        .ok_or_else(|| singular(model, mech))?;
    if !skipped.is_empty() {
        stats.warnings.push(format!(
            "the gas's uncertainty in {} could not be carried into the flywheel's intervals (the gas moved by a standard error could not be integrated): they are too narrow by that part",
            skipped.join(", ")
        ));
    }
    let mut fits = vec![channel(model, p, angle.speed, &train, "train")];
    if let Some((a, b)) = rec.ho {
        fits.push(channel(model, p, angle.speed, &block(a, b), "holdout"));
    }
    Ok(StageFit {
        stage: NAME.into(),
        stats,
        fits,
        iterations,
        evaluations: iterations + 1,
        converged,
        seconds: clock.elapsed().as_secs_f64(),
        series: Vec::new(),
    })
}

/// Residuals `acc - omega'` and their Jacobian in the parameters `mech` (`-d omega'/d p`).
pub(super) fn rows(
    model: &dyn Model,
    p: &[f64],
    speed: usize,
    s: &Samples,
    mech: &[usize],
) -> (DVector<f64>, DMatrix<f64>) {
    let (n, np) = (model.n_states(), model.params().len());
    let mut f = vec![0.0; n];
    let mut jp = vec![0.0; n * np];
    let mut r = DVector::zeros(s.x.len());
    let mut jm = DMatrix::zeros(s.x.len(), mech.len());
    for (k, x) in s.x.iter().enumerate() {
        f.fill(0.0);
        model.rhs(p, x, s.t[k], &mut f);
        jp.fill(0.0);
        let mut sink = JacSink::Dense {
            data: &mut jp,
            nrows: n,
        };
        model.param_jacobian(p, x, s.t[k], &mut sink);
        r[k] = s.acc[k] - f[speed];
        for (c, &j) in mech.iter().enumerate() {
            jm[(k, c)] = jp[speed + n * j];
        }
    }
    (r, jm)
}

/// The Gauss-Newton step `argmin |r - J d|`, the columns equilibrated; `None` when a column
/// is zero or the columns are dependent.
pub(super) fn least_squares(jm: &DMatrix<f64>, r: &DVector<f64>) -> Option<DVector<f64>> {
    let norms: Vec<f64> = jm.column_iter().map(|c| c.norm()).collect();
    if norms.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return None;
    }
    let scaled = DMatrix::from_fn(jm.nrows(), jm.ncols(), |i, j| jm[(i, j)] / norms[j]);
    let svd = scaled.svd(true, true);
    let smax = svd.singular_values.max();
    if svd.singular_values.min() <= 1e-12 * smax {
        return None;
    }
    let d = svd.solve(r, 1e-14 * smax).ok()?;
    Some(DVector::from_iterator(
        d.len(),
        d.iter().zip(&norms).map(|(v, n)| v / n),
    ))
}

/// The estimates with intervals from the angle's noise (`angle_noise.rs`) and the gas's
/// uncertainty (`gas_cov`, `gas_spread.rs`), their correlations and the warnings for
/// correlated pairs.
fn stats(
    model: &dyn Model,
    (p, p0): (&[f64], &[f64]),
    mech: &[usize],
    (r, jm): (&DVector<f64>, &DMatrix<f64>),
    (noise, rec): (&AngleNoise, &Record),
    gas_cov: &DMatrix<f64>,
) -> Option<FitStats> {
    let bread = (jm.transpose() * jm).try_inverse()?;
    let cov = noise.cov(&bread, jm, r, rec) + gas_cov;
    let mut names: Vec<String> = mech
        .iter()
        .map(|&j| model.params()[j].name.to_string())
        .collect();
    let mut values: Vec<(f64, f64)> = mech.iter().zip(p0).map(|(&j, &v0)| (v0, p[j])).collect();
    let g = torque_weights(model, mech, jm);
    let cov = match &g {
        Some(g) => {
            names.push(TORQUE.into());
            let dot = |v: &[f64]| g.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
            let fitted: Vec<f64> = mech.iter().map(|&j| p[j]).collect();
            values.push((dot(p0), dot(&fitted)));
            extend(&cov, g)
        }
        None => cov,
    };
    let k = names.len();
    let se: Vec<f64> = (0..k).map(|a| cov[(a, a)].max(0.0).sqrt()).collect();
    let estimates = (0..k)
        .map(|a| Estimate {
            name: names[a].clone(),
            initial: values[a].0,
            value: values[a].1,
            std_error: se[a],
            ci_low: values[a].1 - 1.96 * se[a],
            ci_high: values[a].1 + 1.96 * se[a],
            model_param: a < mech.len(),
        })
        .collect();
    let corr: Vec<Vec<f64>> = (0..k)
        .map(|a| (0..k).map(|b| cov[(a, b)] / (se[a] * se[b])).collect())
        .collect();
    let mut warnings = Vec::new();
    for a in 0..mech.len() {
        for b in a + 1..mech.len() {
            let names = &names;
            if corr[a][b].abs() > CORRELATED {
                warnings.push(format!(
                    "`{}` and `{}` correlate at {:.3}: at a steady speed the flywheel's friction torques act as one (their sum at the record's speeds is `{TORQUE}`), and the record cannot tell them apart better than their intervals say (a record that speeds up or slows down separates them)",
                    names[a], names[b], corr[a][b]
                ));
            }
        }
    }
    let n = r.len();
    Some(FitStats {
        estimates,
        correlation: corr,
        warnings,
        sigma2: r.norm_squared() / (n.saturating_sub(mech.len())).max(1) as f64,
        samples: n,
    })
}

/// The name of the flywheel's friction and load torque at the record's speeds.
pub const TORQUE: &str = "T_friction";

/// The weights `g` of the torque the free flywheel parameters exert at the record's speeds,
/// `T = sum g_j p_j`, in the unit of a free torque parameter (`N m`: `g = 1` there), from the
/// mean of each one's column against the torque's: `cf` weighs the mean speed, a Coulomb
/// torque or a load its mean `tanh`. `None` with a single free parameter or no torque among
/// them.
fn torque_weights(model: &dyn Model, mech: &[usize], jm: &DMatrix<f64>) -> Option<Vec<f64>> {
    if mech.len() < 2 {
        return None;
    }
    let reference = mech
        .iter()
        .position(|&j| model.params()[j].unit.replace(' ', "") == "Nm")?;
    let mean = |c: usize| jm.column(c).mean();
    let m_ref = mean(reference);
    (m_ref != 0.0 && m_ref.is_finite()).then(|| (0..mech.len()).map(|c| mean(c) / m_ref).collect())
}

/// The covariance `cov` of the parameters extended by the one of `g . p`.
fn extend(cov: &DMatrix<f64>, g: &[f64]) -> DMatrix<f64> {
    let k = cov.nrows();
    let gv = DVector::from_column_slice(g);
    let cg = cov * &gv;
    let mut out = DMatrix::zeros(k + 1, k + 1);
    out.view_mut((0, 0), (k, k)).copy_from(cov);
    for a in 0..k {
        out[(a, k)] = cg[a];
        out[(k, a)] = cg[a];
    }
    out[(k, k)] = gv.dot(&cg);
    out
}

/// How the model's acceleration meets the measured one on a block.
fn channel(model: &dyn Model, p: &[f64], speed: usize, s: &Samples, block: &str) -> ChannelFit {
    let (r, _) = rows(model, p, speed, s, &[]);
    let model_acc: Vec<f64> = s.acc.iter().zip(r.iter()).map(|(a, r)| a - r).collect();
    ChannelFit::plain("omega'", block, &s.acc, &model_acc)
}

/// The error for flywheel parameters the torque balance cannot tell apart (or that act on
/// nothing it sees).
fn singular(model: &dyn Model, mech: &[usize]) -> FitError {
    FitError::KinematicFlywheel {
        model: model.name().into(),
        names: mech
            .iter()
            .map(|&j| model.params()[j].name.to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }
}
