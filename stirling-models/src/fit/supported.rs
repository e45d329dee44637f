//! Which declared engines the two stages can fit today: the measured `p` is read as the
//! pressure of the last control volume and the hot side's as the first, with the sections
//! between them interpolated, so every control volume must be part of that chain (joined
//! to the others by mass-flow links). A CV outside it - a closed bounce space, for one - would
//! be given the cold-side pressure silently; such a model is refused with its name until the
//! sensors are declared with the model.

use stirling_dsl::Model;

use super::FitError;

/// Refuse a model with a control volume outside the working gas's chain of links.
pub fn check_working_gas(model: &dyn Model) -> Result<(), FitError> {
    let topo = model.topology();
    let cvs: Vec<&str> = topo
        .vessels
        .iter()
        .filter(|v| v.is_cv)
        .map(|v| v.name)
        .collect();
    if cvs.len() < 2 {
        return Ok(());
    }
    let base = |s: &'static str| s.split('[').next().unwrap_or(s).trim();
    let linked = |name: &str| {
        topo.links
            .iter()
            .any(|l| base(l.from) == name || base(l.to) == name)
    };
    match cvs.into_iter().find(|cv| !linked(cv)) {
        Some(cv) => Err(FitError::OutsideChain {
            model: model.name().into(),
            vessel: cv.into(),
        }),
        None => Ok(()),
    }
}
