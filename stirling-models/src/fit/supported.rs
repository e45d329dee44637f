//! Which declared engines the two stages can fit: the measured `p` is read as the pressure of the
//! working gas's last control volume and the hot side's as its first, with the sections between
//! them interpolated (the working gas: the CVs joined by mass-flow links to the one `p` observes,
//! [`StateLayout::working_gas`](crate::layout::StateLayout::working_gas)). A CV outside it - a
//! closed bounce space - has a pressure of its own: it must carry a declared sensor the record
//! measures ([`outside_channels`](crate::fit::supported::outside_channels)), or the model is
//! refused with the CV's name; it is never given the working gas's pressure.
//!
//! The sensors a model declares (`sensor p: P_cold "Pa";`) must say the same of the four
//! channels the stages read: `x`, `y` on the two bodies' positions, `p` on the working gas's
//! last CV, `p_hot` on its first. A declaration that puts one elsewhere is refused rather
//! than fitted as if it were where the stages assume.

use stirling_dsl::Model;

use super::FitError;
use crate::data::Measured;
use crate::layout::StateLayout;

/// The states the stages read the seed's channels from: `(channel, state)`.
fn seed_channels(model: &dyn Model) -> Vec<(&'static str, Option<usize>)> {
    let lay = StateLayout::working_gas(model);
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
            let info = model.sensors().iter().find(|s| s.name == channel);
            let state = info.map_or(String::new(), |s| s.definition().to_string());
            let expression = info.is_some_and(|s| !s.expr.is_empty());
            return Err(FitError::SensorPlace {
                model: model.name().into(),
                channel,
                state: if declared.is_some() || expression {
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

/// A CV outside the working gas (a closed bounce space) as the record measures it: the
/// declared sensor on its pressure and that sensor's column.
#[derive(Clone, Debug)]
pub struct OutsideChannel {
    /// The sensor (and column) name.
    pub name: String,
    /// The CV's pressure state.
    pub state: usize,
    pub data: Vec<f64>,
}

/// The measured CVs outside the working gas ([`StateLayout::working_gas`]): each must carry a
/// declared pressure sensor whose column the record has, since the stages cannot give it the
/// working gas's pressure (stage 1 prescribes it from the sensor, stage 2 simulates it and
/// fits the sensor).
pub fn outside_channels(
    model: &dyn Model,
    layout: &StateLayout,
    data: &Measured,
) -> Result<Vec<OutsideChannel>, FitError> {
    let names = model.state_names();
    let mut out = Vec::new();
    for &state in &layout.outside {
        let vessel = names[state].trim_start_matches("P_").to_string();
        let Some(sensor) = model
            .sensors()
            .iter()
            .find(|s| model.sensor_state(s.name) == Some(Some(state)))
        else {
            return Err(FitError::OutsideChain {
                model: model.name().into(),
                vessel,
            });
        };
        let Some(v) = data.channel(sensor.name) else {
            let why = match data.unread(sensor.name) {
                Some(e) => format!("its column could not be read ({e})"),
                None => "the record has no such column".to_string(),
            };
            return Err(FitError::OutsideUnmeasured {
                file: data.source.clone(),
                vessel,
                sensor: sensor.name.into(),
                why,
            });
        };
        out.push(OutsideChannel {
            name: sensor.name.into(),
            state,
            data: v.to_vec(),
        });
    }
    Ok(out)
}
