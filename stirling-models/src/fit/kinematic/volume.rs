//! A kinematic engine's record that logs the working gas's volume instead of the crank angle
//! (lab setups often log `dV [cm^3]`, the volume's change, zero at mid-stroke, from a linear
//! transducer on the power piston): the angle that drives the gas is read back through the
//! model's own volume `V(theta)` (its cranks and spaces, [`crate::sim::indicated::volume_at_angles`]).
//!
//! `V(theta)` rises on one half of a revolution and falls on the other, so a volume is met at
//! two angles; the engine turns forward (the angle grows), so the branch is the one whose
//! slope has the sign of the volume's change in time. Each sample's angle is found on its
//! branch by interpolation in a table of the revolution, and the angles are then joined
//! across revolutions. Near the volume's extremes the branches meet, so noise there moves
//! the angle more but the volume little; the angle is then smoothed by a local quadratic over
//! a revolution, each sample weighted by what its volume says of the angle (`smooth`). A
//! record whose
//! volume swings another amount than the model's is refused: another engine, another unit,
//! or the engine's geometry set wrong.

use std::f64::consts::TAU;

use stirling_dsl::Model;

use crate::data::Measured;
use crate::fit::FitError;
use crate::layout::StateLayout;
use crate::sim::indicated::volume_at_angles;

/// The columns read as the volume, in order: the change from mid-stroke, then the volume.
pub const VOLUME_COLUMNS: [&str; 2] = ["dV", "V"];
/// Angles in the table of one revolution.
const TABLE: usize = 3600;
/// Most the record's volume swing may differ from the model's (a factor either way).
pub const MAX_SWING_RATIO: f64 = 1.3;
/// Half-width of the angle's smoothing, in revolutions. The flywheel's speed ripples within a
/// revolution (the gas's torque: 4 % on the gamma LTD), which a quadratic over a whole
/// revolution cannot follow: on a noiseless record of `tests/fit_kinematic_volume.rs` half a
/// revolution each side biased the angle by -1.2 mrad and `hp` by 1.1 % (outside its
/// interval), a sixth by 0.1 mrad; with the test's noise a sixth keeps every interval on the
/// truth and an eighth lets the regenerator's resistance's widen past its value.
const SMOOTH_REV: f64 = 1.0 / 6.0;
/// Half-width (samples) of the difference that gives the volume's direction.
const SLOPE_HALF: usize = 2;

/// An angle read from a record's volume.
#[derive(Clone, Debug)]
pub struct VolumeAngle {
    /// The volume's column and the flywheel's angle state's name.
    pub column: String,
    pub angle: String,
    /// The angle (rad) at each sample, joined across revolutions.
    pub theta: Vec<f64>,
}

impl VolumeAngle {
    /// What the fit's notes say of it.
    pub fn note(&self) -> String {
        format!(
            "the crank angle `{}` was read from the volume `{}` through the model's volume V(theta) (the engine taken to turn forward)",
            self.angle, self.column
        )
    }
}

/// The angle of the kinematic `model` at parameters `p` read from the volume column of
/// `data`; `None` when the model has no flywheel, the record has its angle, or it has no
/// volume column.
pub fn angle_from_volume(
    model: &dyn Model,
    p: &[f64],
    data: &Measured,
) -> Result<Option<VolumeAngle>, FitError> {
    let Some(&(angle, _)) = StateLayout::flywheels(model).first() else {
        return Ok(None);
    };
    let name = model.state_names()[angle].clone();
    if data.channel(&name).is_some() {
        return Ok(None);
    }
    let Some((column, raw)) = VOLUME_COLUMNS
        .iter()
        .find_map(|c| data.channel(c).map(|v| (*c, v)))
    else {
        return Ok(None);
    };
    let grid: Vec<f64> = (0..TABLE).map(|k| k as f64 * TAU / TABLE as f64).collect();
    let table = volume_at_angles(model, p, &grid)
        .map_err(|e| refuse(model, data, column, &e.to_string()))?;
    let (lo, hi) = extremes(&table);
    let mid = 0.5 * (table[lo] + table[hi]);
    let swing = table[hi] - table[lo];
    let offset = if column == "dV" { mid } else { 0.0 };
    let v: Vec<f64> = raw.iter().map(|d| d + offset).collect();
    check_swing(model, data, column, &v, swing)?;
    let rising = Branch::new(&table, lo, hi);
    let falling = Branch::new(&table, hi, lo);
    let mut out: Vec<f64> = Vec::with_capacity(v.len());
    for k in 0..v.len() {
        let (a, b) = (
            k.saturating_sub(SLOPE_HALF),
            (k + SLOPE_HALF).min(v.len() - 1),
        );
        let branch = if v[b] >= v[a] { &rising } else { &falling };
        let theta = branch.angle(v[k].clamp(table[lo], table[hi]));
        out.push(match out.last() {
            Some(&prev) => prev + (theta - prev + TAU / 2.0).rem_euclid(TAU) - TAU / 2.0,
            None => theta,
        });
    }
    let weight: Vec<f64> = out.iter().map(|&a| slope_at(&table, a).powi(2)).collect();
    Ok(Some(VolumeAngle {
        column: column.to_string(),
        angle: name,
        theta: smooth(&out, &weight),
    }))
}

/// `dV/dtheta` of the revolution's table at the angle `a` (central differences of the table).
fn slope_at(table: &[f64], a: f64) -> f64 {
    let k = (a.rem_euclid(TAU) / TAU * TABLE as f64) as usize % TABLE;
    let (up, dn) = (table[(k + 1) % TABLE], table[(k + TABLE - 1) % TABLE]);
    (up - dn) / (2.0 * TAU / TABLE as f64)
}

/// The angle smoothed by a local quadratic in the sample index over [`SMOOTH_REV`] of a
/// revolution on either side, each sample weighted by `weight` (the squared volume slope at
/// its angle: how much the volume says of the angle there; a volume's noise `s` gives the
/// angle a noise `s / |dV/dtheta|`); the weights keep the samples near the volume's extremes,
/// where the two branches meet and the angle read is poorest, from pulling it.
fn smooth(theta: &[f64], weight: &[f64]) -> Vec<f64> {
    let n = theta.len();
    let turned = (theta[n - 1] - theta[0]).abs().max(TAU);
    let per_rev = n as f64 * TAU / turned;
    let half = ((per_rev * SMOOTH_REV) as usize).clamp(2, n.saturating_sub(1).max(2));
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half).min(n - 1));
            local_quadratic(&theta[a..=b], &weight[a..=b], (k - a) as f64).unwrap_or(theta[k])
        })
        .collect()
}

/// The weighted least-squares quadratic through `(i, y[i])`, evaluated at `at`; `None` when
/// its normal equations are singular.
fn local_quadratic(y: &[f64], w: &[f64], at: f64) -> Option<f64> {
    let mut m = nalgebra::Matrix3::<f64>::zeros();
    let mut r = nalgebra::Vector3::<f64>::zeros();
    for (i, (&yi, &wi)) in y.iter().zip(w).enumerate() {
        let u = i as f64 - at;
        let basis = nalgebra::Vector3::new(1.0, u, u * u);
        m += wi * basis * basis.transpose();
        r += wi * yi * basis;
    }
    let c = m.lu().solve(&r)?;
    c[0].is_finite().then_some(c[0])
}

/// Indices of the least and greatest volume of the table.
fn extremes(table: &[f64]) -> (usize, usize) {
    let mut lo = 0;
    let mut hi = 0;
    for (k, v) in table.iter().enumerate() {
        if *v < table[lo] {
            lo = k;
        }
        if *v > table[hi] {
            hi = k;
        }
    }
    (lo, hi)
}

/// One monotone half of the revolution's table: angles from `from` to `to` (table indices,
/// `to` past `from`, read modulo the table) and their volumes.
struct Branch {
    theta: Vec<f64>,
    volume: Vec<f64>,
}

impl Branch {
    fn new(table: &[f64], from: usize, to: usize) -> Self {
        let to = if to <= from { to + TABLE } else { to };
        let (theta, volume) = (from..=to)
            .map(|k| (k as f64 * TAU / TABLE as f64, table[k % TABLE]))
            .unzip();
        Branch { theta, volume }
    }

    /// The angle of the volume `v` on this branch (linear between the table's angles).
    fn angle(&self, v: f64) -> f64 {
        let up = self.volume.last() >= self.volume.first();
        let k = self
            .volume
            .partition_point(|&w| if up { w < v } else { w > v })
            .clamp(1, self.volume.len() - 1);
        let (v0, v1) = (self.volume[k - 1], self.volume[k]);
        let s = if v1 != v0 { (v - v0) / (v1 - v0) } else { 0.0 };
        self.theta[k - 1] + s.clamp(0.0, 1.0) * (self.theta[k] - self.theta[k - 1])
    }
}

/// Refuse a volume that swings another amount than the model's (`swing`, m^3).
fn check_swing(
    model: &dyn Model,
    data: &Measured,
    column: &str,
    v: &[f64],
    swing: f64,
) -> Result<(), FitError> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    let at = |q: f64| s.get(((s.len() as f64 - 1.0) * q) as usize).copied();
    let (Some(a), Some(b)) = (at(0.005), at(0.995)) else {
        return Err(refuse(model, data, column, "it holds no finite value"));
    };
    let ratio = (b - a) / swing;
    if !(ratio.is_finite() && (1.0 / MAX_SWING_RATIO..=MAX_SWING_RATIO).contains(&ratio)) {
        let why = format!(
            "it swings {:.4} cm^3 where the model's working gas swings {:.4} cm^3 a revolution (a ratio of {ratio:.2}, at most {MAX_SWING_RATIO} either way): another engine, another unit (name it in the header, e.g. `{column} [cm^3]`), or the engine's geometry set wrong",
            1e6 * (b - a),
            1e6 * swing
        );
        return Err(refuse(model, data, column, &why));
    }
    Ok(())
}

fn refuse(model: &dyn Model, data: &Measured, column: &str, why: &str) -> FitError {
    FitError::KinematicColumn {
        file: data.source.clone(),
        model: model.name().into(),
        what: format!("the working gas's volume `{column}` that gives the crank angle"),
        why: format!("its column `{column}`: {why}"),
    }
}
