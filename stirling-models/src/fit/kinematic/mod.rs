//! The fit of a kinematic engine (a flywheel driving cranks, docs/physics.md section 12): the
//! record gives the pressure `p` and the flywheel's angle; stage 2 drives the gas with the
//! measured angle (`stage.rs`) and identifies the free gas parameters and the pressure offset;
//! then, when free parameters act on the flywheel (its friction and load), stage 1 fits them
//! to the wheel's torque balance: the measured angle's acceleration against the fitted gas's
//! torque (`flywheel.rs`). The multiple shooting and the free run (simulations of the free
//! engine) are skipped with a note.

use std::time::Instant;

use stirling_dsl::Model;

use super::classify::classify;
use super::free_run::SensorOffsets;
use super::record::Record;
use super::stage_fit::{fit_stage, FittedStage};
use super::vars::VarKind;
use super::{FitError, FitOptions, Identification};
use crate::layout::StateLayout;

/// The measured angle: the flywheel, the column, the unwrapping and the speed check.
pub mod angle;
/// The angle's noise carried into the flywheel's estimates.
mod angle_noise;
/// Stage 1: the flywheel's friction and load from its torque balance.
pub mod flywheel;
/// The gas's uncertainty carried into the flywheel's estimates.
mod gas_spread;
/// Stage 2 driven by the measured angle.
pub mod stage;
/// The gas's starting state, fitted before the parameters.
pub mod start;
/// The angle read from a record's volume (`dV [cm^3]`) through the model's volume.
pub mod volume;

pub use angle::{measured_angle, unwrap_angle, Angle};

/// The fit of a kinematic engine from the free parameters `free` (names), on the prepared
/// record `rec`.
pub(super) fn identify<'a>(
    model: &'a dyn Model,
    p0: &[f64],
    (layout, rec): (&StateLayout, &Record),
    angle: &Angle,
    free: &[String],
    opts: &FitOptions,
) -> Result<(Identification, Vec<FittedStage<'a>>), FitError> {
    let clock = Instant::now();
    angle::check_speed(angle, rec.data, rec.tr, rec.dt)?;
    let (mech, gas) = classify(model, p0, free)?;
    let (stage, burn) = stage::stage(model, layout, rec, angle, p0, &gas, opts)?;
    let stage = start::fitted_start(stage, rec, burn, opts)?;
    let solved = fit_stage(&stage, rec.tr, rec.ho, burn, opts)?;
    let mut p = p0.to_vec();
    let mut offsets = SensorOffsets {
        p: rec.p_off0,
        p_hot: rec.have_hot.then_some(rec.ph_off0),
        ..Default::default()
    };
    for (v, &val) in stage.vars.iter().zip(&solved.values) {
        match v.kind {
            VarKind::Param(j) => p[j] = val,
            VarKind::Offset { out: 0, .. } => offsets.p = val,
            VarKind::Offset { out: 1, .. } if rec.have_hot => offsets.p_hot = Some(val),
            VarKind::Offset { .. } => {
                let name = v.name.trim_end_matches("_offset").to_string();
                offsets.others.push((name, val));
            }
            _ => {}
        }
    }
    let fitted = FittedStage {
        stage,
        u: solved.lm.x.clone(),
        first: rec.tr.0,
        last: rec.tr.1,
        keep: solved.keep,
    };
    let stage1 = if mech.is_empty() {
        None
    } else {
        let gas = (&fitted, &solved.fit.stats, burn);
        Some(flywheel::fit(model, &mut p, gas, angle, rec, &mech)?)
    };
    let mut notes = vec![format!(
        "kinematic engine: the gas is driven by the measured angle `{}`; {}",
        angle.name,
        if mech.is_empty() {
            "stage 1 (the flywheel's friction and load) does not run: none of its parameters is free"
        } else {
            "stage 1 fits the flywheel's parameters to its torque balance, after the gas"
        }
    )];
    for (asked, what) in [
        (opts.multiple_shooting.is_some(), "multiple shooting"),
        (
            opts.restart_cycles.is_some(),
            "restarts (--restart-cycles, a stage-1 option)",
        ),
        (opts.free_run.is_some(), "free-run validation"),
    ] {
        if asked {
            notes.push(format!("{what}: not run on a kinematic engine"));
        }
    }
    notes.extend(super::identify::at_bounds(model, &p, &gas, &opts.bounds));
    let id = Identification {
        model: model.name().into(),
        n: model.n(),
        params: crate::params::named(model, &p),
        stage1,
        stage2: Some(solved.fit.clone()),
        train: rec.train,
        holdout: rec.holdout,
        seconds: clock.elapsed().as_secs_f64(),
        offsets,
        multiple_shooting: None,
        free_run: None,
        notes,
    };
    Ok((id, vec![fitted]))
}
