//! Root locus over any model parameter: for each value the equilibrium is solved again, the
//! Jacobian reduced on the inventory (section 6) and its poles computed.

use serde::{Deserialize, Serialize};
use stirling_dsl::Model;

use super::equilibrium::NewtonOptions;
use super::poles::Pole;
use super::{dynamic_poles, LinearError};

/// The poles at one parameter value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LocusPoint {
    pub value: f64,
    pub poles: Vec<Pole>,
    /// Equilibrium residual `max |f|` at this value.
    pub residual: f64,
}

/// A root locus.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Locus {
    pub model: String,
    pub param: String,
    pub points: Vec<LocusPoint>,
}

/// `steps` values from `from` to `to` inclusive (`steps >= 2`; one value if `steps == 1`).
pub fn linspace(from: f64, to: f64, steps: usize) -> Vec<f64> {
    match steps {
        0 => Vec::new(),
        1 => vec![from],
        k => (0..k)
            .map(|i| from + (to - from) * i as f64 / (k - 1) as f64)
            .collect(),
    }
}

/// The locus of `param` over `values`, the other parameters as in `p`.
pub fn locus(
    model: &dyn Model,
    p: &[f64],
    param: &str,
    values: &[f64],
    newton: &NewtonOptions,
) -> Result<Locus, LinearError> {
    let k = model
        .param_index(param)
        .ok_or_else(|| LinearError::UnknownParam {
            name: param.to_string(),
            model: model.name().to_string(),
            valid: model
                .params()
                .iter()
                .map(|p| p.name)
                .collect::<Vec<_>>()
                .join(", "),
        })?;
    if values.is_empty() {
        return Err(LinearError::EmptyRange);
    }
    let mut q = p.to_vec();
    let mut points = Vec::with_capacity(values.len());
    for (i, &v) in values.iter().enumerate() {
        q[k] = v;
        let at = |e: LinearError| LinearError::AtValue {
            param: param.to_string(),
            value: v,
            point: i + 1,
            points: values.len(),
            source: Box::new(e),
        };
        crate::params::validate(model, &q).map_err(|e| at(LinearError::Param(e.to_string())))?;
        let d = dynamic_poles(model, &q, newton).map_err(at)?;
        points.push(LocusPoint {
            value: v,
            poles: d.poles,
            residual: d.equilibrium.residual,
        });
    }
    Ok(Locus {
        model: model.name().to_string(),
        param: param.to_string(),
        points,
    })
}
