//! SVG plots (plotters): one file per kind of figure.
// <plot mods>
/// Bode diagram with the margins marked (seed Figure 8).
pub mod bode;
/// Root locus over a parameter.
pub mod locus;
/// Pole map with the right half plane shaded (seed Figure 6).
pub mod poles;
/// PV diagram per vessel over one cycle.
pub mod pv;
/// Start-up time response (x, y, pressures against time).
pub mod timeseries;
