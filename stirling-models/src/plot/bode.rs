//! Bode diagram in the style of the seed's Figure 8: magnitude [dB] above phase [deg] over a
//! logarithmic frequency axis labelled in powers of ten, the 0 dB and -180 deg lines drawn,
//! the selected gain and phase margins marked at their crossovers and written above the
//! panels (never over the curve).
//!
//! [`loop_bode`] is the one Bode figure of a [`Linearization`] (the CLI's `linearize --plot`
//! and the examples draw the same): the broken loop named in the title, over the frequencies
//! of the dominant poles (a decade below the slowest to a decade above the fastest, whole
//! decades), not over the stiff gas poles.

use std::path::Path;

use plotters::prelude::*;

use super::axes;
use super::poles::slow_limit;
use super::DrawError;
use crate::linear::{bode, Bode, Linearization, Margins};

/// The frequency range `(lo, hi)` [rad/s] of the Bode figure of `lin`: whole decades from a
/// decade below the slowest dominant pole (open or closed loop, stiff poles left out as in
/// the pole map) to a decade above the fastest, widened to hold the margins' crossovers.
pub fn loop_range(lin: &Linearization) -> (f64, f64) {
    let poles: Vec<_> = lin
        .dynamics
        .poles
        .iter()
        .chain(&lin.open_loop.poles)
        .collect();
    let limit = slow_limit(poles.iter().copied());
    let m = &lin.margins;
    let (lo, hi) = poles
        .iter()
        .map(|p| p.natural_rad_s)
        .filter(|&w| w > 1e-9 && w <= limit)
        .chain(m.phase_crossover_rad_s)
        .chain(m.gain_crossover_rad_s)
        .fold((f64::INFINITY, 0.0f64), |(l, h), w| (l.min(w), h.max(w)));
    if lo.is_finite() && hi > 0.0 {
        axes::decades(lo / 10.0, hi * 10.0)
    } else {
        (1e-1, 1e4)
    }
}

/// How figures name a model: `nsection (n = 2, full)`.
pub fn model_tag(model: &dyn stirling_dsl::Model) -> String {
    format!("{} (n = {}, {})", model.name(), model.n(), model.closure())
}

/// The Bode figure of the loop of `lin`, broken at its channel; `tag` names the model.
pub fn loop_bode(path: &Path, tag: &str, lin: &Linearization) -> Result<(), DrawError> {
    let (lo, hi) = loop_range(lin);
    let mut w = bode::log_grid(lo, hi, 200);
    let dominant: Vec<_> = lin
        .dynamics
        .poles
        .iter()
        .chain(&lin.open_loop.poles)
        .filter(|p| p.natural_rad_s >= lo && p.natural_rad_s <= hi)
        .cloned()
        .collect();
    w.extend(
        bode::frequency_grid(&dominant, 50)
            .into_iter()
            .filter(|&v| v > lo && v < hi),
    );
    w.sort_by(f64::total_cmp);
    w.dedup_by(|b, a| (*b - *a).abs() <= 1e-12 * a.abs());
    let data = bode::bode(&|w| lin.open_loop.at(w), &w);
    let ol = &lin.open_loop.full;
    let title = format!(
        "Broken loop L(jw) of {tag}, cut at the {} input [{}]",
        ol.name, ol.unit
    );
    bode_diagram(path, &title, &data, &lin.margins)
}

/// Finite `(min, max)` of `v`, padded by `pad`.
fn span(v: &[f64], pad: f64) -> (f64, f64) {
    let (lo, hi) = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    if lo <= hi {
        (lo - pad, hi + pad)
    } else {
        (-pad, pad)
    }
}

/// Draw the Bode diagram of `bode` with `margins` marked to an SVG file.
pub fn bode_diagram(
    path: &Path,
    title: &str,
    bode: &Bode,
    margins: &Margins,
) -> Result<(), DrawError> {
    let err = DrawError::at(path);
    let e = |x: &dyn std::fmt::Display| err(x.to_string());
    let (w0, w1) = (
        bode.w.first().copied().unwrap_or(0.1),
        bode.w.last().copied().unwrap_or(1e4),
    );
    // Shift the phase by whole turns so that the selected phase crossover sits on -180 deg.
    let at = |wc: f64| bode.w.iter().position(|&w| w >= wc).unwrap_or(0);
    let shift = margins.phase_crossover_rad_s.map_or(0.0, |wc| {
        let p = bode.phase_deg.get(at(wc)).copied().unwrap_or(-180.0);
        360.0 * ((-180.0 - p) / 360.0).round()
    });
    let phase: Vec<f64> = bode.phase_deg.iter().map(|p| p + shift).collect();
    let root = SVGBackend::new(path, (800, 740)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let root = root.titled(title, ("sans-serif", 18)).map_err(|x| e(&x))?;
    let (legend, panels) = root.split_vertically(30);
    let (top, bottom) = panels.split_vertically(330);
    let (m0, m1) = span(&bode.mag_db, 5.0);
    let (m0, m1) = (m0.min(-5.0), m1.max(5.0));
    let (p0, p1) = span(&phase, 20.0);
    let (p0, p1) = (p0.min(-200.0), p1.max(-160.0));
    let fdesc = axes::label("Frequency w", "rad/s");
    let mut mag = ChartBuilder::on(&top)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((w0..w1).log_scale(), m0..m1)
        .map_err(|x| e(&x))?;
    mag.configure_mesh()
        .x_label_formatter(&axes::pow10)
        .x_desc(fdesc.as_str())
        .y_desc(axes::label("Magnitude |L|", "dB"))
        .draw()
        .map_err(|x| e(&x))?;
    let pts = |y: &[f64]| -> Vec<(f64, f64)> {
        bode.w
            .iter()
            .copied()
            .zip(y.iter().copied())
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let grey = BLACK.mix(0.5);
    mag.draw_series(LineSeries::new([(w0, 0.0), (w1, 0.0)], grey))
        .map_err(|x| e(&x))?;
    let mut ph = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((w0..w1).log_scale(), p0..p1)
        .map_err(|x| e(&x))?;
    ph.configure_mesh()
        .x_label_formatter(&axes::pow10)
        .x_desc(fdesc.as_str())
        .y_desc(axes::label("Phase of L", "deg"))
        .draw()
        .map_err(|x| e(&x))?;
    ph.draw_series(LineSeries::new([(w0, -180.0), (w1, -180.0)], grey))
        .map_err(|x| e(&x))?;
    let red = RGBColor(200, 0, 0);
    let green = RGBColor(0, 140, 0);
    // Margins first, the curves over them: a marker never hides the curve.
    let mut notes = Vec::new();
    if let (Some(gm), Some(wc)) = (margins.gain_db, margins.phase_crossover_rad_s) {
        // The gain margin: from |L| up (or down) to 0 dB at the phase crossover.
        mag.draw_series(LineSeries::new([(wc, -gm), (wc, 0.0)], red.stroke_width(3)))
            .map_err(|x| e(&x))?;
        ph.draw_series(DashedLineSeries::new(
            [(wc, p0), (wc, p1)],
            4,
            4,
            red.mix(0.6).into(),
        ))
        .map_err(|x| e(&x))?;
        notes.push((format!("Gm = {gm:.2} dB at {wc:.1} rad/s"), red));
    }
    if let (Some(pm), Some(wc)) = (margins.phase_deg, margins.gain_crossover_rad_s) {
        let p = phase.get(at(wc)).copied().unwrap_or(-180.0);
        let base = -180.0 + 360.0 * ((p + 180.0 - pm) / 360.0).round();
        ph.draw_series(LineSeries::new(
            [(wc, base), (wc, base + pm)],
            green.stroke_width(3),
        ))
        .map_err(|x| e(&x))?;
        mag.draw_series(DashedLineSeries::new(
            [(wc, m0), (wc, m1)],
            4,
            4,
            green.mix(0.6).into(),
        ))
        .map_err(|x| e(&x))?;
        notes.push((format!("Pm = {pm:.2} deg at {wc:.1} rad/s"), green));
    }
    if notes.is_empty() {
        notes.push(("no crossover in range: margins undefined".into(), BLACK));
    }
    for (k, (text, color)) in notes.into_iter().enumerate() {
        let style = ("sans-serif", 15).into_font().color(&color);
        legend
            .draw(&Text::new(text, (80 + 330 * k as i32, 6), style))
            .map_err(|x| e(&x))?;
    }
    mag.draw_series(LineSeries::new(pts(&bode.mag_db), BLUE.stroke_width(2)))
        .map_err(|x| e(&x))?;
    ph.draw_series(LineSeries::new(pts(&phase), BLUE.stroke_width(2)))
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))
}
