//! SVG plots (plotters): one file per kind of figure.
// <plot mods>
