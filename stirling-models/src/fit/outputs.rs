//! The record's channels as outputs of the model, for the fits that simulate the whole state
//! (the free run, multiple shooting): the seed's channels and the measured CVs outside the
//! working gas ([`channels`](crate::fit::measured_state::channels)), then every other sensor
//! the model declares whose column the record has - a state elsewhere in the gas
//! (`P_regen[2]`), a wall temperature, or an expression of states and parameters
//! (`P_cold - P_bounce`) - each compared through the model's generated output and its
//! gradient ([`Observation`](stirling_dsl::Observation)).

use stirling_dsl::{Model, Observation};

use super::measured_state::{channels, SensorOffsets};
use super::FitError;
use crate::data::Measured;

/// A measured channel and the model's output it is compared with.
#[derive(Clone, Debug)]
pub struct Output {
    pub name: String,
    pub obs: Observation,
    pub data: Vec<f64>,
}

/// The record's channels the model outputs: [`channels`] first (`x` leads), then the other
/// declared sensors the record measures; a declared sensor whose column the record has but
/// the model cannot output at its `n` is refused by name.
pub fn outputs(model: &dyn Model, data: &Measured) -> Result<Vec<Output>, FitError> {
    let mut out: Vec<Output> = channels(model, data)?
        .into_iter()
        .map(|c| Output {
            name: c.name,
            obs: Observation::state(c.state),
            data: c.data,
        })
        .collect();
    for s in model.sensors() {
        if out.iter().any(|o| o.name == s.name) {
            continue;
        }
        let Some(v) = data.channel(s.name) else {
            continue;
        };
        let obs = Observation::sensor(model, s.name).map_err(|source| FitError::Observe {
            file: data.source.clone(),
            column: s.name.into(),
            source: Box::new(source),
        })?;
        out.push(Output {
            name: s.name.into(),
            obs,
            data: v.to_vec(),
        });
    }
    Ok(out)
}

/// Each output along the trajectory `x` at parameters `p`, offsets added.
pub fn predicted(
    model: &dyn Model,
    p: &[f64],
    outs: &[Output],
    x: &[Vec<f64>],
    off: &SensorOffsets,
) -> Vec<(String, Vec<f64>)> {
    outs.iter()
        .map(|o| {
            let c = off.get(&o.name);
            let y = x.iter().map(|r| o.obs.value(model, p, r) + c).collect();
            (o.name.clone(), y)
        })
        .collect()
}
