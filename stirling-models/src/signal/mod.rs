//! Signal processing shared by the fit, the diagnosis and the rig: smoothing and
//! derivatives, the noise level, cycle detection, harmonics, filters, statistical tails, the bootstrap over cycles.

mod bootstrap;
mod cycles;
mod filters;
mod harmonics;
mod noise;
mod smooth;
mod tails;

pub use bootstrap::{percentile_interval, resamples};
pub use cycles::{crossing_frequency, cycle_frequency, cycle_starts, upward_crossings, Crossing};
pub use filters::{drift_count, first_order_lag, project_drift};
pub use harmonics::{dft, fundamental, wrap};
pub use noise::noise_sigma;
pub use smooth::{derivative, high_pass, savitzky_golay};
pub use tails::{chi2_sf, erfc};
