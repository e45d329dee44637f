//! The gas's starting state for the kinematic stage: the initial masses (the inventory and the
//! temperatures at the window start) and the pressure offsets fitted alone at the starting
//! parameters, before the full fit. From the rest state's temperatures the full fit can
//! settle on another optimum: the gamma LTD's 6 s record (Rf x2, Gleak x3, 10 Pa noise) ended
//! at 94 % with `Rf` on its floor, against 97.7 % from the truth.

use crate::fit::driven::Stage;
use crate::fit::record::Record;
use crate::fit::stage_fit::fit_stage;
use crate::fit::vars::VarKind;
use crate::fit::{FitError, FitOptions};

/// `stage` with the starting values of its initial states and offsets fitted with the model
/// parameters held (samples `burn` skipped at the window start, as the full fit does).
pub fn fitted_start<'a>(
    stage: Stage<'a>,
    rec: &Record,
    burn: usize,
    opts: &FitOptions,
) -> Result<Stage<'a>, FitError> {
    let mut pre = stage.clone();
    pre.vars.retain(|v| !matches!(v.kind, VarKind::Param(_)));
    let quick = FitOptions {
        input_noise_draws: 0,
        ..opts.clone()
    };
    let solved = fit_stage(&pre, rec.tr, None, burn, &quick)?;
    let mut out = stage;
    for (v, &val) in pre.vars.iter().zip(&solved.values) {
        let Some(w) = out.vars.iter_mut().find(|w| w.name == v.name) else {
            continue;
        };
        w.initial = val;
        if let VarKind::Initial(pos) = w.kind {
            out.z0[pos] = val;
        }
    }
    Ok(out)
}
