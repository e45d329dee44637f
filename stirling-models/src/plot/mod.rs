//! SVG plots (plotters): one file per kind of figure.
/// Axis labels with units, power-of-ten ticks.
pub mod axes;
/// Bode diagram with the margins marked (seed Figure 8).
pub mod bode;
/// Root locus over a parameter.
pub mod locus;
/// Pole map with the right half plane shaded (seed Figure 6).
pub mod poles;
/// PV diagram per vessel over one cycle.
pub mod pv;
/// Measured against model, with the residual below (fit figures).
pub mod series;
/// Start-up time response (x, y, pressures against time).
pub mod timeseries;
