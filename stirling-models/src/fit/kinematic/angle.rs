//! The measured crank angle of a kinematic engine: the flywheel it belongs to, the record's
//! column (by the angle state's name, in rad after the header's unit), unwrapped where a
//! counter wraps it at a revolution, and checked against the pressure's cycle: an angle
//! that turns at another rate than the pressure cycles is in another unit, or from another
//! record, and would drive the gas at a wrong speed.

use stirling_dsl::Model;

use crate::data::Measured;
use crate::fit::excitation::{record_frequency, MIN_SAMPLES_PER_CYCLE};
use crate::fit::FitError;
use crate::layout::StateLayout;

/// Most the angle's turning rate may differ from the pressure's cycle frequency (a factor
/// either way; a record in degrees without `[deg]` turns 57 times too fast, and the cycle
/// frequency from the pressure's crossings of its mean may be 10 % off on a noisy record).
pub const MAX_SPEED_RATIO: f64 = 1.5;

/// A kinematic engine's flywheel and its measured angle.
#[derive(Clone, Debug)]
pub struct Angle {
    /// The angle's and the speed's states.
    pub angle: usize,
    pub speed: usize,
    /// The angle's name (the record's column).
    pub name: String,
    /// The measured angle (rad), unwrapped.
    pub data: Vec<f64>,
}

/// The flywheel of `model`, if it is a kinematic engine (`None`: an engine of free bodies),
/// with its angle read from `data`: refused when the model has several flywheels or free
/// bodies besides one, or the record lacks the angle or the pressure `p`.
pub fn measured_angle(model: &dyn Model, data: &Measured) -> Result<Option<Angle>, FitError> {
    let wheels = StateLayout::flywheels(model);
    let Some(&(angle, speed)) = wheels.first() else {
        return Ok(None);
    };
    let positions = StateLayout::of(model).positions.len();
    if wheels.len() > 1 || positions > 1 {
        return Err(FitError::KinematicBodies {
            model: model.name().into(),
            wheels: wheels.len(),
            bodies: positions - wheels.len(),
        });
    }
    let name = model.state_names()[angle].clone();
    let missing = |column: &str, what: &str| {
        let why = match data.unread(column) {
            Some(e) => format!("its column `{column}` could not be read ({e})"),
            None => format!(
                "the record has no column `{column}` (its columns: {})",
                data.channels().join(", ")
            ),
        };
        FitError::KinematicColumn {
            file: data.source.clone(),
            model: model.name().into(),
            what: what.into(),
            why,
        }
    };
    if data.p.is_none() {
        return Err(missing("p", "the pressure `p` its gas is fitted to"));
    }
    let Some(raw) = data.channel(&name) else {
        let what = format!(
            "the flywheel's angle `{name}` (rad, or `{name} [deg]`) that drives its cranks, or the working gas's volume (`dV [cm^3]` from mid-stroke, or `V`) to read it from"
        );
        return Err(missing(&name, &what));
    };
    Ok(Some(Angle {
        angle,
        speed,
        data: unwrap(raw),
        name,
    }))
}

/// Unwrap the flywheel's angle column of `data` in place (a counter that wraps at a
/// revolution, [`unwrap`]), if `model` is a kinematic engine and the record has the column:
/// before the outliers are looked for, to which a wrap looks like a spike.
pub fn unwrap_angle(model: &dyn Model, data: &mut Measured) {
    let Some(&(angle, _)) = StateLayout::flywheels(model).first() else {
        return;
    };
    let name = model.state_names()[angle].clone();
    if let Some(v) = data.channel_mut(&name) {
        *v = unwrap(v);
    }
}

/// The angle with the jumps of a counter that wraps at a revolution (a step larger than
/// pi) removed, when its values stay within one revolution (a counter's); an angle that
/// spans more is left as it is (an angle in degrees read as rad must reach the speed check
/// with its speed, not folded into another).
pub fn unwrap(a: &[f64]) -> Vec<f64> {
    let tau = std::f64::consts::TAU;
    let lo = a.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = a.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !(hi - lo <= 1.01 * tau) {
        return a.to_vec();
    }
    let mut out = Vec::with_capacity(a.len());
    let mut shift = 0.0;
    for (k, &v) in a.iter().enumerate() {
        if k > 0 {
            let step = v - a[k - 1];
            shift -= tau * (step / tau).round();
        }
        out.push(v + shift);
    }
    out
}

/// Fewer revolutions than this on the training block: the engine stands (a stopped engine's
/// pressure still "cycles" at its noise's or its decay's rate, which the speed check would
/// blame on the angle's unit).
const MIN_REVOLUTIONS: f64 = 1.0;

/// Refuse an angle that turns less than one revolution on the training block, or at
/// another rate than the pressure `p` cycles on the training
/// block `tr` (inclusive sample indices, interval `dt`).
pub fn check_speed(
    angle: &Angle,
    data: &Measured,
    tr: (usize, usize),
    dt: f64,
) -> Result<(), FitError> {
    let a = &angle.data;
    let seconds = (tr.1 - tr.0) as f64 * dt;
    let turns = (a[tr.1] - a[tr.0]).abs() / std::f64::consts::TAU / seconds;
    if turns * seconds < MIN_REVOLUTIONS {
        return Err(FitError::KinematicStands {
            file: data.source.clone(),
            angle: angle.name.clone(),
            revolutions: turns * seconds,
            seconds,
        });
    }
    let Some(cycles) = record_frequency(data, tr, dt) else {
        return Ok(()); // the excitation check names a record without a cycle
    };
    let ratio = turns / cycles;
    if !(ratio.is_finite() && (1.0 / MAX_SPEED_RATIO..=MAX_SPEED_RATIO).contains(&ratio)) {
        return Err(FitError::KinematicSpeed {
            file: data.source.clone(),
            angle: angle.name.clone(),
            turns,
            cycles,
        });
    }
    Ok(())
}

/// Refuse a kinematic record sampled too slowly for its flywheel's speed: fewer than
/// [`MIN_SAMPLES_PER_CYCLE`] samples a revolution over the whole record (the angle's
/// turning rate; a record without the angle, or of an engine of free bodies, passes here).
/// At 20 Hz the gamma LTD (2.8 rev/s) gives 7 samples a revolution, and its pressure was
/// refused as a channel that "does not move enough" (its third differences, the noise
/// estimate, are the undersampled cycle's own).
pub fn check_rate(model: &dyn Model, data: &Measured) -> Result<(), FitError> {
    let Some(angle) = measured_angle(model, data)? else {
        return Ok(());
    };
    check_rate_of(&angle, data)
}

/// [`check_rate`] on a measured angle.
pub fn check_rate_of(angle: &Angle, data: &Measured) -> Result<(), FitError> {
    let a = &angle.data;
    let (n, dt) = (a.len(), data.dt());
    if n < 2 || !(dt > 0.0) {
        return Ok(());
    }
    let turns = (a[n - 1] - a[0]).abs() / std::f64::consts::TAU / ((n - 1) as f64 * dt);
    if !(turns > 0.0) || !turns.is_finite() {
        return Ok(());
    }
    let per_rev = 1.0 / (turns * dt);
    // under two samples a revolution (steps over pi) the angle cannot be a sampled rotation:
    // its unit is wrong (degrees read as rad turn 57 times too fast), which the speed check
    // against the pressure's cycle names
    if !(2.0..MIN_SAMPLES_PER_CYCLE).contains(&per_rev) {
        return Ok(());
    }
    Err(FitError::KinematicRate {
        file: data.source.clone(),
        angle: angle.name.clone(),
        rate: 1.0 / dt,
        turns,
        per_rev,
        need: MIN_SAMPLES_PER_CYCLE * turns,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wrapped_counter_is_unwrapped() {
        let tau = std::f64::consts::TAU;
        let true_angle: Vec<f64> = (0..200).map(|k| 0.3 * k as f64 - 1.0).collect();
        let wrapped: Vec<f64> = true_angle.iter().map(|v| v.rem_euclid(tau)).collect();
        let un = unwrap(&wrapped);
        for (a, b) in un.iter().zip(&true_angle) {
            assert!((a - b - (un[0] - true_angle[0])).abs() < 1e-12, "{a} {b}");
        }
        // an angle that never wraps is left alone, and so is one over many revolutions
        // whose steps exceed pi (degrees read as rad)
        assert_eq!(unwrap(&true_angle), true_angle);
        let degrees: Vec<f64> = true_angle.iter().map(|v| v.to_degrees()).collect();
        assert_eq!(unwrap(&degrees), degrees);
    }
}
