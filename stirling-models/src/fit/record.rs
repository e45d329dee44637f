//! The measured record as the stages see it: the uniform time grid, the training and
//! held-out windows as sample indices, the smoothed signals and the first guesses of the
//! sensor offsets.

use stirling_dsl::Model;

use super::sensitivity::Signal;
use super::{FitError, FitOptions};
use crate::data::{cycle_mean, Measured};
use crate::layout::StateLayout;
use crate::signal::savitzky_golay;

/// A record prepared for the two stages.
pub struct Record<'a> {
    pub data: &'a Measured,
    pub t0: f64,
    pub dt: f64,
    /// Savitzky-Golay half-width for the positions (samples); pressures use half of it.
    pub h: usize,
    /// Training block (s) and its inclusive sample indices.
    pub train: (f64, f64),
    pub tr: (usize, usize),
    /// Held-out block (s) and its sample indices.
    pub holdout: Option<(f64, f64)>,
    pub ho: Option<(usize, usize)>,
    /// Whether the hot-side pressure is measured (and the model has more than one CV).
    pub have_hot: bool,
    /// Smoothed pressure signals.
    pub sig_p: Option<Signal>,
    pub sig_ph: Option<Signal>,
    /// Smoothed position signals `x`, `y` (value and derivative), when both are measured.
    pub pos: Option<(Signal, Signal)>,
    /// Whole-cycle means of the positions (first position offsets) and of the pressures
    /// minus the charge pressure (first pressure offsets).
    pub x_off0: [f64; 2],
    pub p_off0: f64,
    pub ph_off0: f64,
    /// The measured CVs outside the working gas (a closed bounce space), in layout order.
    pub outside: Vec<Outside>,
    /// Declared pressure sensors inside the working gas besides `p` and `p_hot` (a
    /// regenerator section) whose columns the record has: outputs of stage 2, each with its
    /// offset, and their CVs' pressures at the window start.
    pub inside: Vec<Outside>,
}

/// A measured CV outside the working gas: its channel, smoothed like `p`, and the first
/// guess of its offset (whole-cycle mean minus the CV's pressure at rest).
pub struct Outside {
    pub name: String,
    /// The CV's pressure state.
    pub state: usize,
    pub raw: Vec<f64>,
    pub sig: Signal,
    pub off0: f64,
}

impl<'a> Record<'a> {
    /// Check the sampling, place the windows and smooth the signals.
    pub fn new(
        model: &dyn Model,
        layout: &StateLayout,
        p: &[f64],
        data: &'a Measured,
        opts: &FitOptions,
    ) -> Result<Self, FitError> {
        let (t0, dt) = uniform(data)?;
        let nt = data.t.len();
        let idx = |t: f64| (((t - t0) / dt).round().max(0.0) as usize).min(nt - 1);
        let t_last = data.t[nt - 1];
        let train = opts.train.unwrap_or((t0, t0 + 0.7 * (t_last - t0)));
        let holdout = match (opts.holdout, opts.train) {
            (Some(h), _) => Some(h),
            (None, None) => Some((train.1, t_last)),
            (None, Some(_)) => None,
        };
        let tr = (idx(train.0), idx(train.1));
        if tr.1 < tr.0 + 10 {
            return Err(FitError::ShortTraining {
                from: train.0,
                to: train.1,
                samples: tr.1.saturating_sub(tr.0) + 1,
            });
        }
        // the cycle against the model's first: an aliased record (sampled at 1 s for a 13 Hz
        // engine) shows a slow cycle that the excitation check would blame on a still engine
        // (a record without motion passes it, and the excitation check names it)
        super::excitation::check_model_frequency(model, p, data, tr, dt)?;
        super::excitation::check(data, tr, dt)?;
        let outliers = crate::data::outliers::find(data);
        if let Some(first) = outliers.first() {
            return Err(FitError::Outliers {
                file: data.source.clone(),
                count: outliers.len(),
                first: first.to_string(),
            });
        }
        let h = ((opts.smooth / dt).round() as usize).max(3);
        let ps = &layout.pressures;
        let have_hot = data.p_hot.is_some() && ps.len() > 1;
        let mut eq = vec![0.0; model.n_states()];
        model.equilibrium_guess(p, &mut eq);
        let pmean = ps.first().map(|&i| eq[i]).unwrap_or(0.0);
        let mean_of = |v: Option<&Vec<f64>>, base: f64| v.map(|v| cycle_mean(v) - base);
        let smooth = |v: &Vec<f64>| signal(t0, dt, v, (h / 2).max(3));
        let outside = super::supported::outside_channels(model, layout, data)?
            .into_iter()
            .map(|c| Outside {
                sig: smooth(&c.data),
                off0: cycle_mean(&c.data) - eq[c.state],
                name: c.name,
                state: c.state,
                raw: c.data,
            })
            .collect();
        let inside = inside_channels(model, layout, data)
            .into_iter()
            .map(|(name, state, raw)| Outside {
                sig: smooth(&raw),
                off0: cycle_mean(&raw) - eq[state],
                name,
                state,
                raw,
            })
            .collect();
        Ok(Self {
            inside,
            data,
            t0,
            dt,
            h,
            train,
            tr,
            holdout,
            ho: holdout.map(|h| (idx(h.0), idx(h.1))),
            have_hot,
            sig_p: data.p.as_ref().map(smooth),
            sig_ph: data.p_hot.as_ref().map(smooth),
            pos: data
                .x
                .as_ref()
                .zip(data.y.as_ref())
                .map(|(x, y)| (signal(t0, dt, x, h), signal(t0, dt, y, h))),
            x_off0: [
                mean_of(data.x.as_ref(), 0.0).unwrap_or(0.0),
                mean_of(data.y.as_ref(), 0.0).unwrap_or(0.0),
            ],
            p_off0: mean_of(data.p.as_ref(), pmean).unwrap_or(0.0),
            ph_off0: mean_of(data.p_hot.as_ref(), pmean).unwrap_or(0.0),
            outside,
        })
    }
}

/// The declared sensors on the working gas's pressures other than the ones `p` and `p_hot`
/// are read from, whose columns the record has: `(name, state, samples)`.
fn inside_channels(
    model: &dyn Model,
    layout: &StateLayout,
    data: &Measured,
) -> Vec<(String, usize, Vec<f64>)> {
    let ps = &layout.pressures;
    let read = [ps.first(), ps.last()];
    model
        .sensors()
        .iter()
        .filter(|s| !matches!(s.name, "p" | "p_hot" | "x" | "y"))
        .filter_map(|s| {
            let state = model.sensor_state(s.name).flatten()?;
            let inside = ps.contains(&state) && !read.contains(&Some(&state));
            let v = data.channel(s.name).filter(|_| inside)?;
            Some((s.name.to_string(), state, v.to_vec()))
        })
        .collect()
}

/// The start time and the interval of a uniformly sampled record.
fn uniform(data: &Measured) -> Result<(f64, f64), FitError> {
    if data.t.len() < 20 {
        return Err(FitError::TooFewSamples {
            file: data.source.clone(),
            samples: data.t.len(),
        });
    }
    let dt = crate::data::check_uniform(data, None).map_err(FitError::Sampling)?;
    Ok((data.t[0], dt))
}

/// A smoothed signal (quartic Savitzky-Golay of half-width `h`).
pub fn signal(t0: f64, dt: f64, y: &[f64], h: usize) -> Signal {
    let (val, der) = savitzky_golay(y, dt, h, 4);
    Signal { t0, dt, val, der }
}
