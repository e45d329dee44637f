//! The fit report: estimates, standard errors, 95 % intervals, correlations, a collinearity
//! warning, and the fit percentage `100 (1 - |y - yhat| / |y - mean y|)` per channel.

use nalgebra::DMatrix;
use serde::Serialize;

/// One estimated quantity.
#[derive(Clone, Debug, Serialize)]
pub struct Estimate {
    pub name: String,
    pub initial: f64,
    pub value: f64,
    pub std_error: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    /// A model parameter (false: an offset or an initial state).
    pub model_param: bool,
}

impl Estimate {
    /// Whether `v` lies in the 95 % interval.
    pub fn covers(&self, v: f64) -> bool {
        self.ci_low <= v && v <= self.ci_high
    }
}

/// Fit percentage of one channel on one block.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelFit {
    pub channel: String,
    pub block: String,
    /// Fit percentage of the model output; in a stage fitted with a drift band projected
    /// out ([`super::driven::Stage::drift`]), of the output with that band of the error
    /// removed (the criterion's view).
    pub fit_percent: f64,
    /// Fit percentage of the raw model output (equal to `fit_percent` without a drift band).
    pub fit_percent_raw: f64,
    pub rms: f64,
    pub samples: usize,
}

impl ChannelFit {
    /// The fit of the model output `yhat` to `y` (no drift band removed).
    pub fn plain(channel: &str, block: &str, y: &[f64], yhat: &[f64]) -> Self {
        let fp = fit_percent(y, yhat);
        let rms = (y
            .iter()
            .zip(yhat)
            .map(|(u, v)| (u - v) * (u - v))
            .sum::<f64>()
            / y.len() as f64)
            .sqrt();
        ChannelFit {
            channel: channel.to_string(),
            block: block.into(),
            fit_percent: fp,
            fit_percent_raw: fp,
            rms,
            samples: y.len(),
        }
    }
}

/// The statistics of a least-squares fit.
#[derive(Clone, Debug, Serialize)]
pub struct FitStats {
    pub estimates: Vec<Estimate>,
    pub correlation: Vec<Vec<f64>>,
    /// Pairs with |correlation| above 0.95, and a conditioning note.
    pub warnings: Vec<String>,
    /// Residual variance factor `s^2 = RSS / (N - k)` (about 1 when the noise model holds).
    pub sigma2: f64,
    pub samples: usize,
}

/// `100 (1 - |y - yhat| / |y - mean y|)`.
pub fn fit_percent(y: &[f64], yhat: &[f64]) -> f64 {
    let m = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let e: f64 = y
        .iter()
        .zip(yhat)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    let d: f64 = y.iter().map(|a| (a - m) * (a - m)).sum::<f64>().sqrt();
    100.0 * (1.0 - e / d)
}

/// Estimates and correlations from the Jacobian of the weighted residuals `r` with respect to
/// variables `u`, where quantity `k` is `initial_k + scale_k u_k`.
pub fn stats(
    names: &[(String, bool)],
    initial: &[f64],
    scale: &[f64],
    u: &[f64],
    r: &[f64],
    j: &DMatrix<f64>,
) -> FitStats {
    stats_with_nuisance(names, initial, scale, u, r, j, 0)
}

/// [`stats`] when `nuisance` further linear coefficients were projected out of `r` and `j`
/// (they cost degrees of freedom but are not reported).
pub fn stats_with_nuisance(
    names: &[(String, bool)],
    initial: &[f64],
    scale: &[f64],
    u: &[f64],
    r: &[f64],
    j: &DMatrix<f64>,
    nuisance: usize,
) -> FitStats {
    stats_full(names, initial, scale, u, r, j, nuisance, None)
}

/// [`stats_with_nuisance`] plus `extra`, a further covariance of `u` (e.g. from the noise on
/// prescribed inputs, which the residual variance does not see: see
/// [`super::driven::Stage::input_noise_cov`]), added to `s^2 (J^T J)^-1`.
pub fn stats_full(
    names: &[(String, bool)],
    initial: &[f64],
    scale: &[f64],
    u: &[f64],
    r: &[f64],
    j: &DMatrix<f64>,
    nuisance: usize,
    extra: Option<&DMatrix<f64>>,
) -> FitStats {
    let (nr, k) = (r.len(), u.len());
    let rss: f64 = r.iter().map(|v| v * v).sum();
    let sigma2 = rss / (nr.saturating_sub(k + nuisance)).max(1) as f64;
    let jtj = j.transpose() * j;
    // invert on the unit-diagonal scaling for conditioning
    let d: Vec<f64> = (0..k).map(|i| jtj[(i, i)].max(1e-300).sqrt()).collect();
    let scaled = DMatrix::from_fn(k, k, |a, b| jtj[(a, b)] / (d[a] * d[b]));
    let inv = scaled
        .clone()
        .try_inverse()
        .unwrap_or_else(|| scaled.clone().pseudo_inverse(1e-14).expect("svd"));
    let cov = DMatrix::from_fn(k, k, |a, b| {
        sigma2 * inv[(a, b)] / (d[a] * d[b]) + extra.map_or(0.0, |e| e[(a, b)])
    });
    let estimates = (0..k)
        .map(|i| estimate(&names[i], initial[i], scale[i], u[i], cov[(i, i)]))
        .collect();
    let correlation: Vec<Vec<f64>> = (0..k)
        .map(|a| {
            (0..k)
                .map(|b| cov[(a, b)] / (cov[(a, a)] * cov[(b, b)]).sqrt())
                .collect()
        })
        .collect();
    let mut warnings = collinear_warnings(names, &correlation);
    warnings.extend(conditioning_warning(scaled));
    FitStats {
        estimates,
        correlation,
        warnings,
        sigma2,
        samples: nr,
    }
}

/// One estimate from its scaled value `u` and variance `var` (95 % interval).
fn estimate(name: &(String, bool), initial: f64, scale: f64, u: f64, var: f64) -> Estimate {
    let se = var.max(0.0).sqrt() * scale.abs();
    let v = initial + scale * u;
    Estimate {
        name: name.0.clone(),
        initial,
        value: v,
        std_error: se,
        ci_low: v - 1.96 * se,
        ci_high: v + 1.96 * se,
        model_param: name.1,
    }
}

/// A warning for each pair of estimates correlated beyond 0.95.
fn collinear_warnings(names: &[(String, bool)], correlation: &[Vec<f64>]) -> Vec<String> {
    let k = correlation.len();
    let mut warnings = Vec::new();
    for a in 0..k {
        for b in a + 1..k {
            if correlation[a][b].abs() > 0.95 {
                warnings.push(format!(
                    "`{}` and `{}` are nearly collinear (correlation {:.3}): the data cannot separate them; fix one or add excitation",
                    names[a].0, names[b].0, correlation[a][b]
                ));
            }
        }
    }
    warnings
}

/// A warning when the scaled information matrix is ill-conditioned.
fn conditioning_warning(scaled: DMatrix<f64>) -> Option<String> {
    let ev = scaled.symmetric_eigen().eigenvalues;
    let (lo, hi) = ev
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &e| (l.min(e), h.max(e)));
    (lo <= hi * 1e-10).then(|| format!("the scaled information matrix is ill-conditioned (condition number {:.2e}): some combination of the free parameters is not identifiable", hi / lo.max(1e-300)))
}
