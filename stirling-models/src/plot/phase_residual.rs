//! The residual (measured minus model) by phase of the cycle, in physical units, one panel
//! per channel: the mean waveform of the record minus that of a simulation, each taken over
//! its own cycles, so that a frequency error does not smear the shape. A line at zero is a
//! model whose cycle has the record's shape; the before and after lines show what the
//! leading effect changed, and where in the cycle.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{axes, DrawError};

/// One channel's residual lines (`name`, one value per phase bin, in SI units).
pub struct Panel<'a> {
    pub channel: &'a str,
    pub lines: Vec<(&'a str, &'a [f64])>,
}

/// The display scale and unit of a channel (positions in mm, pressures in kPa).
fn scale(channel: &str) -> (f64, &'static str) {
    match axes::channel_unit(channel) {
        "m" => (1e3, "mm"),
        "Pa" => (1e-3, "kPa"),
        _ => (1.0, "-"),
    }
}

/// Draw the panels stacked, phase of the cycle \[deg\] on the horizontal axes.
pub fn phase_residual(path: &Path, title: &str, panels: &[Panel]) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let k = panels.len().max(1);
    let root = SVGBackend::new(path, (900, 40 + 260 * k as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 18))
        .map_err(|e| err(&e))?;
    for (pi, (area, panel)) in root.split_evenly((k, 1)).iter().zip(panels).enumerate() {
        draw_panel(area, panel, pi == 0, path)?;
    }
    root.present().map_err(|e| err(&e))
}

/// One channel's panel; the first carries the legend, in headroom above the lines.
fn draw_panel(
    area: &DrawingArea<SVGBackend, Shift>,
    panel: &Panel,
    first: bool,
    path: &Path,
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let (s, unit) = scale(panel.channel);
    let lim = panel
        .lines
        .iter()
        .flat_map(|l| l.1.iter())
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max((s * v).abs()))
        .max(1e-12)
        * 1.1;
    let top = if first { 1.8 * lim } else { lim };
    let mut c = ChartBuilder::on(area)
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..360.0, -lim..top)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .y_labels(7)
        .y_label_formatter(&axes::linear_ticks(top + lim))
        .x_desc(axes::label("phase of the cycle", "deg"))
        .y_desc(axes::label(
            &format!("{} measured - model", panel.channel),
            unit,
        ))
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(vec![(0.0, 0.0), (360.0, 0.0)], BLACK))
        .map_err(|e| err(&e))?;
    for (li, (name, v)) in panel.lines.iter().enumerate() {
        // the calibrated model in blue; after it, red, then the palette's other colours
        let color = match li {
            0 => BLUE.to_rgba(),
            1 => RED.to_rgba(),
            k => Palette99::pick(k + 1).to_rgba(),
        };
        let bin = 360.0 / v.len().max(1) as f64;
        let pts: Vec<(f64, f64)> = v
            .iter()
            .enumerate()
            .filter(|p| p.1.is_finite())
            .map(|(i, y)| ((i as f64 + 0.5) * bin, s * y))
            .collect();
        c.draw_series(LineSeries::new(pts, color.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    if first {
        c.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .border_style(BLACK)
            .background_style(WHITE)
            .draw()
            .map_err(|e| err(&e))?;
    }
    Ok(())
}
