//! Measured points against model lines over time (the diagnosis's held-out block: the
//! calibrated model and the model with the leading effect), and below them each line's
//! residual (measured minus model): at the scale of the signal the lines cover each other,
//! at the scale of the residual their difference is what the figure is for.

use std::ops::Range;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{axes, DrawError};

/// The colours of the model lines, in order (blue: before, red: after).
const LINES: [RGBColor; 3] = [BLUE, RED, GREEN];

/// Draw `measured` (dots) and each `(name, values)` line of `channel` against `t` \[s\], with
/// the residuals in a second panel.
pub fn overlay(
    path: &Path,
    title: &str,
    channel: &str,
    t: &[f64],
    measured: &[f64],
    lines: &[(&str, &[f64])],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let m = points(t, measured);
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    let (lo, hi) = extent(m.iter().map(|p| p.1));
    if !(lo <= hi) || !(t0 < t1) {
        return Err(err(&"no finite measured samples to draw"));
    }
    let root = SVGBackend::new(path, (900, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(title, ("sans-serif", 18))
        .map_err(|e| err(&e))?;
    let (top, bottom) = root.split_vertically(360);
    signal_panel(&top, channel, t0..t1, (lo, hi), &m, t, lines).map_err(|e| err(&e))?;
    residual_panel(&bottom, channel, t0..t1, t, measured, lines).map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}

/// The finite `(t, v)` pairs.
fn points(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter()
        .zip(v)
        .filter(|p| p.1.is_finite())
        .map(|(&a, &b)| (a, b))
        .collect()
}

/// The smallest and largest of `v`.
fn extent(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::MAX, f64::MIN), |(l, h), x| (l.min(x), h.max(x)))
}

/// The measured dots and the model lines, the legend in headroom above them.
fn signal_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    channel: &str,
    span: Range<f64>,
    (lo, hi): (f64, f64),
    m: &[(f64, f64)],
    t: &[f64],
    lines: &[(&str, &[f64])],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let pad = 0.05 * (hi - lo).max(1e-12);
    let top = hi + 0.45 * (hi - lo).max(1e-12);
    let mut c = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(span, (lo - pad)..top)?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::channel_label(channel))
        .y_label_formatter(&axes::linear_ticks(top - lo))
        .draw()?;
    c.draw_series(m.iter().map(|&p| Circle::new(p, 1, BLACK.filled())))?
        .label("measured")
        .legend(|(x, y)| Circle::new((x + 10, y), 2, BLACK.filled()));
    for (k, (name, v)) in lines.iter().enumerate() {
        let color = LINES[k % LINES.len()];
        c.draw_series(LineSeries::new(points(t, v), color))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
}

/// Each line's residual, measured minus model, about a zero line.
fn residual_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    channel: &str,
    span: Range<f64>,
    t: &[f64],
    measured: &[f64],
    lines: &[(&str, &[f64])],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let resid: Vec<Vec<f64>> = lines
        .iter()
        .map(|(_, v)| measured.iter().zip(*v).map(|(a, b)| a - b).collect())
        .collect();
    let (lo, hi) = extent(resid.iter().flatten().copied().filter(|v| v.is_finite()));
    let lim = lo.abs().max(hi.abs()).max(1e-12) * 1.05;
    let mut c = ChartBuilder::on(area)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(span.clone(), -lim..lim)?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::label(
            &format!("{channel} measured - model"),
            axes::channel_unit(channel),
        ))
        .y_label_formatter(&axes::linear_ticks(2.0 * lim))
        .draw()?;
    c.draw_series(LineSeries::new(
        vec![(span.start, 0.0), (span.end, 0.0)],
        BLACK,
    ))?;
    for (k, r) in resid.iter().enumerate() {
        let color = LINES[k % LINES.len()];
        c.draw_series(LineSeries::new(points(t, r), color))?;
    }
    Ok(())
}
