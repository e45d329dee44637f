//! Which declared engines the two stages can fit today: the measured `p` is read as the
//! pressure of the last control volume and the hot side's as the first, with the sections
//! between them interpolated, so every control volume must be part of that chain (joined
//! to the others by mass-flow links). A CV outside it - a closed bounce space, for one - would
//! be given the cold-side pressure silently; such a model is refused with its name.
//!
//! The sensors a model declares (`sensor p: P_cold "Pa";`) must say the same of the four
//! channels the stages read: `x`, `y` on the two bodies' positions, `p` on the last CV's
//! pressure, `p_hot` on the first's. A declaration that puts one elsewhere is refused rather
//! than fitted as if it were where the stages assume.

use stirling_dsl::Model;

use super::FitError;
use crate::layout::StateLayout;

/// The states the stages read the seed's channels from: `(channel, state)`.
fn seed_channels(model: &dyn Model) -> Vec<(&'static str, Option<usize>)> {
    let lay = StateLayout::of(model);
    vec![
        ("x", lay.positions.first().copied()),
        ("y", lay.positions.get(1).copied()),
        ("p", lay.pressures.last().copied()),
        ("p_hot", lay.pressures.first().copied()),
    ]
}

/// Refuse a model whose declared sensors `x`, `y`, `p`, `p_hot` observe other states than
/// the stages read them from.
pub fn check_sensors(model: &dyn Model) -> Result<(), FitError> {
    let names = model.state_names();
    for (channel, assumed) in seed_channels(model) {
        let Some(declared) = model.sensor_state(channel) else {
            continue;
        };
        if declared != assumed || declared.is_none() {
            let at = |s: Option<usize>| s.map_or("no state".to_string(), |k| names[k].clone());
            let state = model
                .sensors()
                .iter()
                .find(|s| s.name == channel)
                .map_or(String::new(), |s| s.state.to_string());
            return Err(FitError::SensorPlace {
                model: model.name().into(),
                channel,
                state: if declared.is_some() {
                    state
                } else {
                    format!("{state} (absent at this n and closure)")
                },
                expected: at(assumed),
            });
        }
    }
    Ok(())
}

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
