//! SVG plots (plotters): one file per kind of figure. Every figure of the project is drawn
//! here; the analyses hand over numbers.
/// Bars per group (the diagnosis's residual by phase and by harmonic).
pub mod bars;
/// The error of a figure that could not be drawn.
mod error;
pub use error::DrawError;
/// Axis labels with units, power-of-ten ticks.
pub mod axes;
/// Bode diagram with the margins marked (seed Figure 8).
pub mod bode;
/// Root locus over a parameter.
pub mod locus;
/// Measured points against two model lines over time (before and after an effect).
pub mod overlay;
/// Mean residual by phase of the cycle, before and after an effect, one panel per channel.
pub mod phase_residual;
/// Pole map with the right half plane shaded (seed Figure 6).
pub mod poles;
/// PV diagram per vessel over one cycle.
pub mod pv;
/// A record's p-V loop against a model's, and their pressure difference by crank angle.
pub mod pv_record;
/// Measured against model, with the residual below (fit figures).
pub mod series;
/// A two-parameter sweep as a map of power with the stability boundary.
pub mod sweep_map;
/// Start-up time response (x, y, pressures against time).
pub mod timeseries;
/// The diagnosis's gap, step by step.
pub mod waterfall;
