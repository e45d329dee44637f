//! The flywheel's friction on a kinematic engine: does it differ from the file's?
//!
//! The diagnosis drives the gas by the measured angle, so the flywheel's friction and load
//! act on none of its rows, and a record of an engine whose bearings rub more than the file
//! says diagnoses `no_significant_gap` on the gas. The kinematic fit's stage 1 sees them: the
//! wheel's torque balance on the measured angular acceleration, after the gas
//! ([`crate::fit::kinematic`], `flywheel.rs`). Here that fit runs with the file's friction
//! parameters freed beside the calibrated gas, and their torque at the record's speeds
//! (`T_friction`, or the one parameter when the file has one) is tested against the file's
//! value: a z-test on its estimate, whose standard error carries the angle's noise and the
//! gas's uncertainty, at the diagnosis's per-candidate level.

use serde::Serialize;
use stirling_dsl::Model;

use super::DiagnoseError;
use crate::data::Measured;
use crate::fit::kinematic::flywheel::TORQUE;
use crate::fit::{identify_stages, FitOptions};
use crate::signal::chi2_sf;

/// The units of the flywheel's friction parameters: a viscous coefficient and a torque.
pub const FRICTION_UNITS: [&str; 2] = ["N m s", "N m"];

/// The flywheel's friction torque as the record gives it, against the file's.
#[derive(Clone, Debug, Serialize)]
pub struct FlywheelFriction {
    /// What is compared: [`TORQUE`] (the free parameters' torque at the record's speeds) or
    /// the one friction parameter.
    pub name: String,
    pub unit: String,
    /// The file's value, the fitted one and its 95 % interval.
    pub file_value: f64,
    pub value: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    /// Of the test that the record's value is the file's.
    pub p_value: f64,
    /// `p_value` below the diagnosis's per-candidate level.
    pub differs: bool,
}

impl FlywheelFriction {
    /// The sentence the verdict's reason ends with.
    pub fn sentence(&self) -> String {
        let what = if self.differs {
            "differs from the file's: the flywheel's friction or load is not the file's (not a gas effect)"
        } else {
            "agrees with the file's"
        };
        format!(
            "; the flywheel's friction torque at the record's speeds, fitted from the angle's acceleration, is {:.3e} [{:.3e}, {:.3e}] {} against the file's {:.3e} (p {:.1e}): it {what}",
            self.value, self.ci_low, self.ci_high, self.unit, self.file_value, self.p_value
        )
    }
}

/// The file's friction parameters of the flywheel: of a unit of [`FRICTION_UNITS`], nonzero
/// at `p0`, and acting on the mechanics only.
pub fn friction_params(model: &dyn Model, p0: &[f64]) -> Vec<String> {
    super::kinematic::acting_params(model, p0, &FRICTION_UNITS, true)
}

/// The check on the record `data` with the calibration's options `fit_opts` (its free gas
/// parameters and blocks); `None` when the file's flywheel has no friction parameter.
pub fn check(
    model: &dyn Model,
    p0: &[f64],
    data: &Measured,
    fit_opts: &FitOptions,
    level: f64,
) -> Result<Option<FlywheelFriction>, DiagnoseError> {
    let friction = friction_params(model, p0);
    if friction.is_empty() {
        return Ok(None);
    }
    let mut o = fit_opts.clone();
    let mut free = o.free.clone().unwrap_or_default();
    for f in &friction {
        if !free.contains(f) {
            free.push(f.clone());
        }
    }
    o.free = Some(free);
    let (id, _) = identify_stages(model, p0, data, &o)?;
    let name = if friction.len() > 1 {
        TORQUE
    } else {
        friction[0].as_str()
    };
    let Some(e) = id.estimate(name) else {
        return Ok(None);
    };
    let unit = model
        .param_index(name)
        .map_or("N m", |j| model.params()[j].unit);
    let z = (e.value - e.initial) / e.std_error;
    let p_value = if z.is_finite() {
        chi2_sf(z * z, 1)
    } else {
        f64::NAN
    };
    Ok(Some(FlywheelFriction {
        name: name.into(),
        unit: unit.into(),
        file_value: e.initial,
        value: e.value,
        ci_low: e.ci_low,
        ci_high: e.ci_high,
        p_value,
        differs: p_value < level,
    }))
}
