//! A measured channel resolved on one model: which states its output reads at the model's
//! `n` and closure, its value and its gradient along a trajectory.

use super::model::Model;

/// Why a channel cannot be observed on a model.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ObserveError {
    #[error("model `{model}` declares no sensor `{sensor}` (it declares: {known})")]
    Unknown {
        model: String,
        sensor: String,
        known: String,
    },
    #[error("sensor `{sensor}` of model `{model}` reads `{state}`, which this model has no state for at n = {n} (an array element beyond n, or a mass state of the frozen closure)")]
    Absent {
        model: String,
        sensor: String,
        state: String,
        n: usize,
    },
}

/// A channel as a function of the state: one state, or a declared sensor's output over the
/// states it reads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Observation {
    /// The declared sensor (index into [`Model::sensors`]); `None`: the state `reads[0]`.
    sensor: Option<usize>,
    /// The states read, in the order the output takes them.
    reads: Vec<usize>,
}

impl Observation {
    /// The state `i` itself.
    pub fn state(i: usize) -> Self {
        Self {
            sensor: None,
            reads: vec![i],
        }
    }

    /// The declared sensor `name` of `model`, its reads resolved at the model's `n` and
    /// closure.
    pub fn sensor(model: &dyn Model, name: &str) -> Result<Self, ObserveError> {
        let sensors = model.sensors();
        let Some(k) = sensors.iter().position(|s| s.name == name) else {
            let known: Vec<&str> = sensors.iter().map(|s| s.name).collect();
            return Err(ObserveError::Unknown {
                model: model.name().into(),
                sensor: name.into(),
                known: if known.is_empty() {
                    "none".into()
                } else {
                    known.join(", ")
                },
            });
        };
        let names = model.state_names();
        let reads = sensors[k]
            .reads
            .iter()
            .map(|r| {
                names
                    .iter()
                    .position(|s| s == r)
                    .ok_or_else(|| ObserveError::Absent {
                        model: model.name().into(),
                        sensor: name.into(),
                        state: (*r).into(),
                        n: model.n(),
                    })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            sensor: Some(k).filter(|&k| !sensors[k].expr.is_empty()),
            reads,
        })
    }

    /// The one state observed, when the channel is a state.
    pub fn as_state(&self) -> Option<usize> {
        match self.sensor {
            None => Some(self.reads[0]),
            Some(_) => None,
        }
    }

    /// The states the output reads.
    pub fn reads(&self) -> &[usize] {
        &self.reads
    }

    /// The output at state `x`.
    pub fn value(&self, model: &dyn Model, p: &[f64], x: &[f64]) -> f64 {
        let mut dv = vec![0.0; self.reads.len()];
        let mut dp = vec![0.0; p.len()];
        self.gradient(model, p, x, &mut dv, &mut dp)
    }

    /// The output at state `x`; writes its derivative in each read state to `dv` (in
    /// [`Observation::reads`] order) and in each parameter to `dp` (entries it does not
    /// depend on untouched).
    pub fn gradient(
        &self,
        model: &dyn Model,
        p: &[f64],
        x: &[f64],
        dv: &mut [f64],
        dp: &mut [f64],
    ) -> f64 {
        match self.sensor {
            None => {
                dv[0] = 1.0;
                x[self.reads[0]]
            }
            Some(k) => {
                let v: Vec<f64> = self.reads.iter().map(|&i| x[i]).collect();
                model.sensor_output(k, p, &v, dv, dp)
            }
        }
    }
}
