//! End stops seen in the measured acceleration (an equation-error test, no simulation).
//!
//! A body between stops is an impact oscillator: driven by the measured pressure, one run of
//! the model settles on another response than the engine's, and a restarted run trades a soft
//! stop against a wrong driving force (docs/diagnosis.md, "Why the stops beside a leak
//! fail"). The stops also show without any run: where a body meets its stop, its measured
//! acceleration bends away from what the smooth forces give. Each body's acceleration (the
//! second derivative of its smoothed position) is regressed on a *linear-in-coefficients
//! null* that spans what every other effect and the gas do to it - the positions, velocities
//! and measured pressure, the running integral of the pressure (a leak's slow mass change),
//! a Coulomb sign, a quadratic damping, and the square and cube of the body's own position
//! (a gas spring's and a hardening flexure's curvature) - and then on that null plus a hinge
//! `(q - c)` beyond a travel `c` on one side, profiled over the largest travels the record
//! shows. The hinge's coefficient is `-kc / m`; the share of the null's residual it removes
//! is the statistic. Every signal goes through the same smoothing, so the regression holds
//! for the smoothed signals as it does for the true ones (a linear filter commutes with the
//! linear combination).

use nalgebra::{DMatrix, DVector};

use crate::data::Measured;
use crate::signal::savitzky_golay;

/// Half-width of the smoothing window, seconds (about a 20th of a cycle at 15 Hz).
const SMOOTH_S: f64 = 0.002;
/// Travels tried on each side: quantiles of the body's position, from this one outward.
const TRAVEL_QUANTILES: [f64; 12] = [
    0.80, 0.84, 0.87, 0.90, 0.92, 0.94, 0.95, 0.96, 0.97, 0.98, 0.99, 0.995,
];

/// One side of one body at its best travel.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StopSide {
    /// The body's position channel (`x` or `y`).
    pub channel: String,
    /// `+1` the upper side, `-1` the lower.
    pub side: i8,
    /// The travel (position where the stop begins, m, in the record's coordinates).
    pub travel: f64,
    /// The hinge's coefficient (1/s^2): `-kc / m` for a stop.
    pub coefficient: f64,
    /// Share of the null's residual variance the hinge removes.
    pub share: f64,
    /// Samples beyond the travel.
    pub beyond: usize,
}

/// The smoothed signals of a record.
struct Smoothed {
    p: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    vx: Vec<f64>,
    vy: Vec<f64>,
    ax: Vec<f64>,
    ay: Vec<f64>,
    p_int: Vec<f64>,
}

fn smooth2(v: &[f64], dt: f64, h: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (s, d) = savitzky_golay(v, dt, h, 4);
    let (ss, _) = savitzky_golay(&s, dt, h, 4);
    let (ds, dd) = savitzky_golay(&d, dt, h, 4);
    (ss, ds, dd)
}

fn smoothed(data: &Measured) -> Option<Smoothed> {
    let dt = data.dt();
    let h = ((SMOOTH_S / dt).round() as usize).max(3);
    let (p, x, y) = (data.channel("p")?, data.channel("x")?, data.channel("y")?);
    // the pressure needs no derivative: smoothed twice like the positions' values
    let (ps, _) = savitzky_golay(&savitzky_golay(p, dt, h, 4).0, dt, h, 4);
    let (xs, vx, ax) = smooth2(x, dt, h);
    let (ys, vy, ay) = smooth2(y, dt, h);
    let mean = ps.iter().sum::<f64>() / ps.len() as f64;
    let mut acc = 0.0;
    let p_int = ps
        .iter()
        .map(|v| {
            acc += (v - mean) * dt;
            acc
        })
        .collect();
    Some(Smoothed {
        p: ps,
        x: xs,
        y: ys,
        vx,
        vy,
        ax,
        ay,
        p_int,
    })
}

/// The null's columns for a body (`own` position, `vel` velocity).
fn null_columns(s: &Smoothed, own: &[f64], vel: &[f64]) -> Vec<Vec<f64>> {
    let n = own.len();
    let scale = own.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    let vscale = vel.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-12);
    let t: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
    vec![
        vec![1.0; n],
        t,
        s.x.clone(),
        s.y.clone(),
        s.vx.clone(),
        s.vy.clone(),
        s.p.clone(),
        s.p_int.clone(),
        vel.iter().map(|v| (v / (0.02 * vscale)).tanh()).collect(),
        vel.iter().map(|v| v * v.abs()).collect(),
        own.iter().map(|q| (q / scale).powi(2)).collect(),
        own.iter().map(|q| (q / scale).powi(3)).collect(),
    ]
}

/// Residual sum of squares of `acc` on `cols` (rows `lo..hi`) and the last column's coefficient.
fn lsq(cols: &[Vec<f64>], acc: &[f64], lo: usize, hi: usize) -> Option<(f64, f64)> {
    let m = hi - lo;
    let k = cols.len();
    let norms: Vec<f64> = cols
        .iter()
        .map(|c| {
            c[lo..hi]
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt()
                .max(1e-300)
        })
        .collect();
    let a = DMatrix::from_fn(m, k, |i, j| cols[j][lo + i] / norms[j]);
    let b = DVector::from_fn(m, |i, _| acc[lo + i]);
    let svd = a.clone().svd(true, true);
    let x = svd.solve(&b, 1e-12).ok()?;
    let r = &b - &a * &x;
    Some((r.norm_squared(), x[k - 1] / norms[k - 1]))
}

/// The value below which a share `q` of `v` lies.
fn quantile(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

/// A stop is seen when its hinge removes more than this share of the null's residual variance
/// of the body's acceleration. On the self-check's records (p,x,y, 2 s at 2 kHz, both seeds)
/// every record with end stops gave 0.077 to 0.36 (the least beside a quadratic regenerator
/// loss that halves the stroke), every record without gave at most 0.006 (22 records: clean,
/// leak, Coulomb friction, quadratic loss, a hardening spring, speed-dependent heat transfer,
/// and pairs of these; docs/diagnosis.md, "End stops seen in the acceleration").
pub const SEEN_SHARE: f64 = 0.03;

/// Points of the fine search between the neighbours of the best coarse travel.
const FINE: usize = 12;

/// The hinge of side `side` at travel `c` on `own`.
fn hinge(own: &[f64], c: f64, side: i8) -> Vec<f64> {
    own.iter()
        .map(|v| {
            if (v - c) * side as f64 > 0.0 {
                v - c
            } else {
                0.0
            }
        })
        .collect()
}

/// The side at travel `c`, when its coefficient restores.
fn side_at(
    (null, rss0): (&[Vec<f64>], f64),
    (own, acc): (&[f64], &[f64]),
    (lo, hi): (usize, usize),
    (c, side): (f64, i8),
) -> Option<(f64, f64, usize)> {
    let h = hinge(own, c, side);
    let beyond = h[lo..hi].iter().filter(|v| **v != 0.0).count();
    let mut cols = null.to_vec();
    cols.push(h);
    let (rss, coef) = lsq(&cols, acc, lo, hi)?;
    (coef < 0.0).then_some((1.0 - rss / rss0, coef, beyond))
}

/// The best travel of one side: the coarse quantile grid, then a fine grid around its best.
fn best_side(
    null: (&[Vec<f64>], f64),
    (own, acc): (&[f64], &[f64]),
    (lo, hi): (usize, usize),
    side: i8,
) -> Option<(f64, (f64, f64, usize))> {
    let qs: Vec<f64> = TRAVEL_QUANTILES
        .iter()
        .map(|q| quantile(&own[lo..hi], if side > 0 { *q } else { 1.0 - q }))
        .collect();
    let at = |c: f64| side_at(null, (own, acc), (lo, hi), (c, side)).map(|r| (c, r));
    type Found = Option<(f64, (f64, f64, usize))>;
    let better = |a: Found, b: Found| match (a, b) {
        (Some(a), Some(b)) if b.1 .0 > a.1 .0 => Some(b),
        (None, b) => b,
        (a, _) => a,
    };
    let (i, coarse) = qs
        .iter()
        .enumerate()
        .fold((0, None), |(bi, best), (i, &c)| {
            let next = better(best, at(c));
            if next.map(|n| n.0) == Some(c) {
                (i, next)
            } else {
                (bi, next)
            }
        });
    coarse?;
    let (a, b) = (qs[i.saturating_sub(1)], qs[(i + 1).min(qs.len() - 1)]);
    (0..=FINE)
        .map(|k| a + (b - a) * k as f64 / FINE as f64)
        .fold(coarse, |best, c| better(best, at(c)))
}

/// Each body's best stop on each side (the travel whose hinge removes most of the null's
/// residual), over samples `lo..hi` of `data` (`p`, `x`, `y` needed; `None` otherwise).
pub fn probe(data: &Measured, lo: usize, hi: usize) -> Option<Vec<StopSide>> {
    let s = smoothed(data)?;
    // the smoothing's window at each end is skewed: keep away from it
    let margin = ((SMOOTH_S / data.dt()).round() as usize).max(3) * 3;
    let (lo, hi) = (lo + margin, hi.min(data.len()).saturating_sub(margin));
    if hi <= lo + 100 {
        return None;
    }
    let mut out = Vec::new();
    for (name, own, vel, acc) in [("x", &s.x, &s.vx, &s.ax), ("y", &s.y, &s.vy, &s.ay)] {
        let null = null_columns(&s, own, vel);
        let (rss0, _) = lsq(&null, acc, lo, hi)?;
        for side in [1i8, -1] {
            let best = best_side((&null, rss0), (own, acc), (lo, hi), side);
            out.extend(best.map(|(travel, (share, coefficient, beyond))| StopSide {
                channel: name.into(),
                side,
                travel,
                coefficient,
                share,
                beyond,
            }));
        }
    }
    Some(out)
}

/// The sides whose stops are seen ([`SEEN_SHARE`]), the strongest side of each body.
pub fn seen(data: &Measured, lo: usize, hi: usize) -> Vec<StopSide> {
    let mut out: Vec<StopSide> = Vec::new();
    for s in probe(data, lo, hi).unwrap_or_default() {
        if s.share <= SEEN_SHARE {
            continue;
        }
        match out.iter_mut().find(|o| o.channel == s.channel) {
            Some(o) if o.share < s.share => *o = s,
            Some(_) => {}
            None => out.push(s),
        }
    }
    out
}
