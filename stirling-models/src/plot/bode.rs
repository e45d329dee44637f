//! Bode diagram in the style of the seed's Figure 8: magnitude \[dB\] above phase \[deg\] over a
//! logarithmic frequency axis labelled in powers of ten, the 0 dB and -180 deg lines drawn,
//! the selected gain and phase margins marked at their crossovers and written above the
//! panels (never over the curve).
//!
//! [`loop_bode`](crate::plot::bode::loop_bode) is the one Bode figure of a
//! [`Linearization`](crate::linear::Linearization) (the CLI's `linearize --plot` and the examples
//! draw the same): the broken loop named in the title, over the frequencies of the dominant poles
//! (a decade below the slowest to a decade above the fastest, whole decades), not over the stiff
//! gas poles.

use std::path::Path;

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
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

/// A panel of the figure: a log frequency axis [rad/s] over a linear one.
type Panel<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, RangedCoordf64>>;

/// The index of the first frequency of `w` at or above `wc` (0 if none).
fn index_at(w: &[f64], wc: f64) -> usize {
    w.iter().position(|&w| w >= wc).unwrap_or(0)
}

/// The phase shift by whole turns that puts the selected phase crossover on -180 deg.
fn turn_shift(bode: &Bode, margins: &Margins) -> f64 {
    margins.phase_crossover_rad_s.map_or(0.0, |wc| {
        let p = bode
            .phase_deg
            .get(index_at(&bode.w, wc))
            .copied()
            .unwrap_or(-180.0);
        360.0 * ((-180.0 - p) / 360.0).round()
    })
}

/// A panel on `area` over the frequencies `w` and the values `y`, with its mesh drawn.
fn panel<'a, 'b>(
    path: &Path,
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    w: (f64, f64),
    y: (f64, f64),
    ydesc: String,
) -> Result<Panel<'a, 'b>, DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let mut chart = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((w.0..w.1).log_scale(), y.0..y.1)
        .map_err(|x| e(&x))?;
    let fdesc = axes::label("Frequency w", "rad/s");
    chart
        .configure_mesh()
        .x_label_formatter(&axes::pow10)
        .x_desc(fdesc.as_str())
        .y_desc(ydesc)
        .draw()
        .map_err(|x| e(&x))?;
    Ok(chart)
}

/// Mark the gain margin `gm` at the phase crossover `wc`: a bar from |L| to 0 dB, a dashed
/// line over the phase panel (its range `p`).
fn mark_gain(
    path: &Path,
    (mag, ph): (&mut Panel, &mut Panel),
    gm: f64,
    wc: f64,
    p: (f64, f64),
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let red = RGBColor(200, 0, 0);
    mag.draw_series(LineSeries::new([(wc, -gm), (wc, 0.0)], red.stroke_width(3)))
        .map_err(|x| e(&x))?;
    ph.draw_series(DashedLineSeries::new(
        [(wc, p.0), (wc, p.1)],
        4,
        4,
        red.mix(0.6).into(),
    ))
    .map_err(|x| e(&x))?;
    Ok(())
}

/// Mark the phase margin `pm` at the gain crossover `wc` from the nearest -180 deg line
/// `base`: a bar on the phase panel, a dashed line over the magnitude panel (its range `m`).
fn mark_phase(
    path: &Path,
    (mag, ph): (&mut Panel, &mut Panel),
    (pm, base): (f64, f64),
    wc: f64,
    m: (f64, f64),
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let green = RGBColor(0, 140, 0);
    ph.draw_series(LineSeries::new(
        [(wc, base), (wc, base + pm)],
        green.stroke_width(3),
    ))
    .map_err(|x| e(&x))?;
    mag.draw_series(DashedLineSeries::new(
        [(wc, m.0), (wc, m.1)],
        4,
        4,
        green.mix(0.6).into(),
    ))
    .map_err(|x| e(&x))?;
    Ok(())
}

/// Mark the margins that exist (under the curves); the notes for the legend.
fn mark_margins(
    path: &Path,
    (mag, ph): (&mut Panel, &mut Panel),
    margins: &Margins,
    (w, phase): (&[f64], &[f64]),
    (m, p): ((f64, f64), (f64, f64)),
) -> Result<Vec<(String, RGBColor)>, DrawError> {
    let mut notes = Vec::new();
    if let (Some(gm), Some(wc)) = (margins.gain_db, margins.phase_crossover_rad_s) {
        // The gain margin: from |L| up (or down) to 0 dB at the phase crossover.
        mark_gain(path, (&mut *mag, &mut *ph), gm, wc, p)?;
        notes.push((
            format!("Gm = {gm:.2} dB at {wc:.1} rad/s"),
            RGBColor(200, 0, 0),
        ));
    }
    if let (Some(pm), Some(wc)) = (margins.phase_deg, margins.gain_crossover_rad_s) {
        let pc = phase.get(index_at(w, wc)).copied().unwrap_or(-180.0);
        let base = -180.0 + 360.0 * ((pc + 180.0 - pm) / 360.0).round();
        mark_phase(path, (mag, ph), (pm, base), wc, m)?;
        notes.push((
            format!("Pm = {pm:.2} deg at {wc:.1} rad/s"),
            RGBColor(0, 140, 0),
        ));
    }
    if notes.is_empty() {
        notes.push(("no crossover in range: margins undefined".into(), BLACK));
    }
    Ok(notes)
}

/// Write the margin notes side by side in the legend strip.
fn write_notes(
    path: &Path,
    legend: &DrawingArea<SVGBackend, Shift>,
    notes: Vec<(String, RGBColor)>,
) -> Result<(), DrawError> {
    for (k, (text, color)) in notes.into_iter().enumerate() {
        let style = ("sans-serif", 15).into_font().color(&color);
        legend
            .draw(&Text::new(text, (80 + 330 * k as i32, 6), style))
            .map_err(|x| DrawError::on(path, &x))?;
    }
    Ok(())
}

/// Draw the Bode diagram of `bode` with `margins` marked to an SVG file.
pub fn bode_diagram(
    path: &Path,
    title: &str,
    bode: &Bode,
    margins: &Margins,
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let (w0, w1) = (
        bode.w.first().copied().unwrap_or(0.1),
        bode.w.last().copied().unwrap_or(1e4),
    );
    // Shift the phase by whole turns so that the selected phase crossover sits on -180 deg.
    let shift = turn_shift(bode, margins);
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
    let ylabel = axes::label("Magnitude |L|", "dB");
    let mut mag = panel(path, &top, (w0, w1), (m0, m1), ylabel)?;
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
    let ylabel = axes::label("Phase of L", "deg");
    let mut ph = panel(path, &bottom, (w0, w1), (p0, p1), ylabel)?;
    ph.draw_series(LineSeries::new([(w0, -180.0), (w1, -180.0)], grey))
        .map_err(|x| e(&x))?;
    // Margins first, the curves over them: a marker never hides the curve.
    let ranges = ((m0, m1), (p0, p1));
    let notes = mark_margins(
        path,
        (&mut mag, &mut ph),
        margins,
        (&bode.w, &phase),
        ranges,
    )?;
    write_notes(path, &legend, notes)?;
    mag.draw_series(LineSeries::new(pts(&bode.mag_db), BLUE.stroke_width(2)))
        .map_err(|x| e(&x))?;
    ph.draw_series(LineSeries::new(pts(&phase), BLUE.stroke_width(2)))
        .map_err(|x| e(&x))?;
    root.present().map_err(|x| e(&x))
}
