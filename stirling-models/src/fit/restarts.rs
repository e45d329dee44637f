//! Stage runs restarted from the measured state: the window cut into segments of a few
//! cycles, each started from the free states the record shows at its first sample.

use super::driven::Stage;
use super::sensitivity::{Column, Driven, Signal};
use super::FitError;

/// Restarts of a driven run from the measured state every `every` samples: the run is cut
/// into segments of a few cycles, each started from the free states the record shows at its
/// first sample, so that a run cannot drift onto another response of the driven subsystem
/// (a piston between end stops is an impact oscillator with several responses to one
/// forcing). The sensitivities restart at zero: a later segment does not depend on the
/// initial-state variables.
#[derive(Clone, Debug)]
pub struct Restarts {
    pub every: usize,
    /// The free states at every sample of the record, from the smoothed measurements.
    pub states: Vec<Vec<f64>>,
    /// The channel each free state is read from (a position and its velocity from the
    /// position's channel): a gain on that sensor divides the restart state as it divides
    /// the measurement (as `Stage::apply_sensors` does).
    pub channels: Vec<&'static str>,
}

impl Stage<'_> {
    /// [`Stage::integrate_window`] over `first..=last` in segments of [`Restarts::every`]
    /// samples, each after the first started from the measured state with its sensitivities
    /// at zero; a segment's first row is the last row of the segment before. `gain[o]` is
    /// output `o`'s sensor gain factor: a restart state read from that output's channel is
    /// divided by it (the states are measurements, not the bodies' true positions).
    pub(super) fn integrate_restarted(
        &self,
        sys: &Driven,
        z0: &[f64],
        (first, last): (usize, usize),
        r: &Restarts,
        gain: &[f64],
    ) -> Result<Vec<Vec<f64>>, FitError> {
        let factor = self.restart_factors(r, gain);
        let mut rows = self.integrate_window(sys, z0, r.every)?;
        // a later segment does not depend on the initial-state variables: their columns
        // start at zero there (an input column that moves nothing)
        let mut seg = sys.clone();
        for c in &mut seg.columns {
            if let Column::Initial { scale, .. } = *c {
                *c = Column::Input {
                    du: vec![0.0; sys.given.len()],
                    scale,
                };
            }
        }
        let mut a = first + r.every;
        while a < last {
            let b = (a + r.every).min(last);
            let shift = (a - first) as f64 * self.dt;
            for (s, orig) in seg.signals.iter_mut().zip(&sys.signals) {
                *s = Signal {
                    t0: orig.t0 - shift,
                    ..orig.clone()
                };
            }
            let mut za: Vec<f64> = r.states[a]
                .iter()
                .zip(&factor)
                .map(|(z, f)| z / f)
                .collect();
            za.resize(sys.free.len(), 0.0);
            rows.extend(self.integrate_window(&seg, &za, b - a)?.into_iter().skip(1));
            a = b;
        }
        Ok(rows)
    }

    /// The gain factor of each restart state: that of the output read from its channel (1
    /// without one).
    fn restart_factors(&self, r: &Restarts, gain: &[f64]) -> Vec<f64> {
        r.channels
            .iter()
            .map(|c| {
                self.outputs
                    .iter()
                    .position(|o| o.channel == *c)
                    .map_or(1.0, |o| gain[o])
            })
            .collect()
    }
}
