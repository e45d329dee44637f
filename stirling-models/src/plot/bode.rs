//! Bode diagram in the style of the seed's Figure 8: magnitude (dB) above phase (deg) over a
//! logarithmic frequency axis, the 0 dB and -180 deg lines drawn, and the selected gain and
//! phase margins marked at their crossover frequencies.

use std::path::Path;

use plotters::prelude::*;

use super::poles::DrawError;
use crate::linear::{Bode, Margins};

/// Draw the Bode diagram of `bode` with `margins` marked to an SVG file.
pub fn bode_diagram(
    path: &Path,
    title: &str,
    bode: &Bode,
    margins: &Margins,
) -> Result<(), DrawError> {
    let err = DrawError::at(path);
    let (w0, w1) = (bode.w[0], *bode.w.last().unwrap_or(&1.0));
    // Shift the phase by whole turns so that the selected phase crossover sits on -180 deg.
    let shift = margins.phase_crossover_rad_s.map_or(0.0, |wc| {
        let i = bode.w.iter().position(|&w| w >= wc).unwrap_or(0);
        360.0 * ((-180.0 - bode.phase_deg[i]) / 360.0).round()
    });
    let phase: Vec<f64> = bode.phase_deg.iter().map(|p| p + shift).collect();
    let root = SVGBackend::new(path, (800, 700)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
    let root = root
        .titled(title, ("sans-serif", 20))
        .map_err(|e| err(e.to_string()))?;
    let (top, bottom) = root.split_vertically(340);
    let range = |v: &[f64], pad: f64| {
        let lo = v
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::INFINITY, f64::min);
        let hi = v
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(f64::NEG_INFINITY, f64::max);
        (lo - pad, hi + pad)
    };
    let (m0, m1) = range(&bode.mag_db, 5.0);
    let (p0, p1) = range(&phase, 20.0);
    let (p0, p1) = (p0.min(-200.0), p1.max(-160.0));
    let mut mag = ChartBuilder::on(&top)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d((w0..w1).log_scale(), m0.min(-5.0)..m1.max(5.0))
        .map_err(|e| err(e.to_string()))?;
    mag.configure_mesh()
        .y_desc("Magnitude (dB)")
        .draw()
        .map_err(|e| err(e.to_string()))?;
    let pts = |y: &[f64]| {
        bode.w
            .iter()
            .copied()
            .zip(y.iter().copied())
            .collect::<Vec<_>>()
    };
    mag.draw_series(LineSeries::new(pts(&bode.mag_db), BLUE.stroke_width(2)))
        .map_err(|e| err(e.to_string()))?;
    mag.draw_series(LineSeries::new([(w0, 0.0), (w1, 0.0)], BLACK.mix(0.5)))
        .map_err(|e| err(e.to_string()))?;
    let mut ph = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((w0..w1).log_scale(), p0..p1)
        .map_err(|e| err(e.to_string()))?;
    ph.configure_mesh()
        .x_desc("Frequency (rad/s)")
        .y_desc("Phase (deg)")
        .draw()
        .map_err(|e| err(e.to_string()))?;
    ph.draw_series(LineSeries::new(pts(&phase), BLUE.stroke_width(2)))
        .map_err(|e| err(e.to_string()))?;
    ph.draw_series(LineSeries::new(
        [(w0, -180.0), (w1, -180.0)],
        BLACK.mix(0.5),
    ))
    .map_err(|e| err(e.to_string()))?;
    let style = ("sans-serif", 16).into_font().color(&RED);
    if let (Some(gm), Some(wc)) = (margins.gain_db, margins.phase_crossover_rad_s) {
        // The gain margin: from |L| up (or down) to 0 dB at the phase crossover.
        mag.draw_series(LineSeries::new([(wc, -gm), (wc, 0.0)], RED.stroke_width(3)))
            .map_err(|e| err(e.to_string()))?;
        ph.draw_series(LineSeries::new([(wc, p0), (wc, p1)], RED.mix(0.4)))
            .map_err(|e| err(e.to_string()))?;
        let text = format!("Gm = {gm:.2} dB (at {wc:.1} rad/s)");
        top.draw(&Text::new(text, (80, 20), style.clone()))
            .map_err(|e| err(e.to_string()))?;
    }
    if let (Some(pm), Some(wc)) = (margins.phase_deg, margins.gain_crossover_rad_s) {
        let i = bode.w.iter().position(|&w| w >= wc).unwrap_or(0);
        let base = -180.0 + 360.0 * ((phase[i] + 180.0 - pm) / 360.0).round();
        ph.draw_series(LineSeries::new(
            [(wc, base), (wc, base + pm)],
            GREEN.stroke_width(3),
        ))
        .map_err(|e| err(e.to_string()))?;
        mag.draw_series(LineSeries::new(
            [(wc, m0.min(-5.0)), (wc, m1.max(5.0))],
            GREEN.mix(0.4),
        ))
        .map_err(|e| err(e.to_string()))?;
        let text = format!("Pm = {pm:.2} deg (at {wc:.1} rad/s)");
        top.draw(&Text::new(text, (80, 42), style.color(&GREEN)))
            .map_err(|e| err(e.to_string()))?;
    }
    root.present().map_err(|e| err(e.to_string()))
}
