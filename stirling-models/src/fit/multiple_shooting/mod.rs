//! Multiple-shooting refinement: the training block is cut into segments of a few cycles, each
//! simulated freely (nothing prescribed) from its own initial state; the weighted output error of
//! all segments is minimised jointly over the free model parameters, the sensor offsets and every
//! segment's initial state, by [`crate::fit::lm`].
//!
//! Why: a self-excited oscillator drifts in phase over a long free run, so a single-shooting
//! output error is dominated by the drift; over segments of about two cycles it is not, and the
//! free segment states absorb the state noise.
//!
//! The Jacobian comes from forward sensitivities of each free segment, `S' = f_x S + f_p` with
//! `S(0) = [I | 0]` (columns: initial states, then parameters), integrated as a
//! [`Driven`](crate::fit::sensitivity::Driven) system with every state free. The segment joins are
//! not constrained: their mismatch (the defects, in units of each state's scale) is reported as a
//! consistency check.
//!
//! Cost: each segment integrates `n (1 + n + free)` states with a dense Jacobian, so the
//! refinement suits the small models (`cv1`: 0.3 s on 0.5 s of data); on `nsection` n = 2
//! (11 states) it takes minutes in the dev profile, and the fast gas modes (pressure
//! differences along the regenerator, mass shares) make the segments' gas initial states
//! nearly collinear (reported in the warnings) although the model parameters stay separable.

mod problem;
mod setup;

use std::time::Instant;

use serde::Serialize;
use stirling_dsl::Model;

use super::free_run::{sample_range, SensorOffsets};
use super::outputs::outputs;
use super::report::{self, ChannelFit, FitStats};
use super::{lm, FitError};
use crate::data::Measured;
use crate::fit::vars::param_bounds;
use crate::sim::{state_scale, SimOptions};
use problem::Problem;
use setup::{cut_segments, output_vars, param_vars, segment_vars};

/// Options of the refinement.
#[derive(Clone, Debug)]
pub struct MsOptions {
    /// Cycles per segment.
    pub cycles: f64,
    /// Longest span of the training block used, from its start (s); keeps the cost bounded.
    pub span: f64,
    /// Fit the sensor offsets too (otherwise they stay at their given values).
    pub offsets: bool,
    /// Half-width of the smoothing window for the initial states (s).
    pub smooth: f64,
    pub lm: lm::LmOptions,
    pub sim: SimOptions,
    /// Bounds `(name, lo, hi)` over those the model declares (as
    /// [`FitOptions::bounds`](crate::fit::FitOptions::bounds)).
    pub bounds: Vec<(String, f64, f64)>,
}

impl Default for MsOptions {
    fn default() -> Self {
        Self {
            cycles: 2.0,
            span: 0.5,
            offsets: true,
            smooth: 0.006,
            lm: lm::LmOptions::stage(),
            sim: SimOptions::default(),
            bounds: Vec::new(),
        }
    }
}

/// One segment.
#[derive(Clone, Debug, Serialize)]
pub struct Segment {
    pub t0: f64,
    pub t1: f64,
    /// Largest `|x_end(previous) - x0(this)| / scale` over the states (0 for the first).
    pub defect: f64,
}

/// The refinement's result.
#[derive(Clone, Debug, Serialize)]
pub struct MultipleShooting {
    /// Estimates of the model parameters, offsets and segment initial states (`seg<k>.<state>`).
    pub stats: FitStats,
    /// All model parameters after the refinement.
    pub params: Vec<(String, f64)>,
    pub offsets: SensorOffsets,
    pub segments: Vec<Segment>,
    /// Fit per channel over the segments (block `segments`).
    pub fits: Vec<ChannelFit>,
    pub iterations: usize,
    pub evaluations: usize,
    pub converged: bool,
    pub seconds: f64,
}

impl MultipleShooting {
    pub fn estimate(&self, name: &str) -> Option<&report::Estimate> {
        self.stats.estimates.iter().find(|e| e.name == name)
    }
}

/// Refine the parameters `free` (indices) of `model` from `p0` and the offsets `off` by multiple
/// shooting over the training block `block` of `data`.
pub fn multiple_shooting(
    model: &dyn Model,
    p0: &[f64],
    free: &[usize],
    data: &Measured,
    off: &SensorOffsets,
    block: (f64, f64),
    opts: &MsOptions,
) -> Result<MultipleShooting, FitError> {
    let clock = Instant::now();
    let ch = outputs(model, data)?;
    let dt = data.dt();
    let end = block.1.min(block.0 + opts.span);
    let (a, b) = sample_range(data, block, end, "multiple shooting", 21)?;
    let segs = cut_segments(&ch, (a, b), dt, block, opts.cycles)?;
    let h = ((opts.smooth / dt).round() as usize).max(3);
    let sscale = state_scale(model, p0);
    let mut vars = param_vars(model, p0, free);
    let outputs = output_vars(&ch, off, &sscale, opts.offsets, &mut vars);
    segment_vars(model, p0, data, off, &segs, (h, &sscale), &mut vars)?;
    let prob = Problem {
        model,
        p: p0.to_vec(),
        free: free.to_vec(),
        bounds: free
            .iter()
            .map(|&j| param_bounds(model, j, &opts.bounds))
            .collect(),
        outs: outputs.outs,
        off0: outputs.off0,
        segs,
        vars,
        n_off: outputs.n_off,
        dt,
        zscale: sscale,
        sim: opts.sim,
    };
    let res = prob.solve(&opts.lm)?;
    let stats = prob.stats(&res);
    let fin = prob.eval(&res.x, false)?;
    let th = prob.values(&res.x);
    Ok(MultipleShooting {
        stats,
        params: crate::params::named(model, &prob.params_with(&th)),
        offsets: prob.offsets_at(&th, off),
        segments: prob.segments(&fin, &th, &data.t),
        fits: prob.fits(&fin, a),
        iterations: res.iterations,
        evaluations: res.evaluations,
        converged: res.converged,
        seconds: clock.elapsed().as_secs_f64(),
    })
}
