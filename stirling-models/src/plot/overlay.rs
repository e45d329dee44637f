//! Measured points against model lines over time (the diagnosis's held-out block: the
//! calibrated model and the model with the leading effect).

use std::path::Path;

use plotters::prelude::*;

use super::{axes, DrawError};

/// The colours of the model lines, in order (blue: before, red: after).
const LINES: [RGBColor; 3] = [BLUE, RED, GREEN];

/// Draw `measured` (dots) and each `(name, values)` line of `channel` against `t` [s].
pub fn overlay(
    path: &Path,
    title: &str,
    channel: &str,
    t: &[f64],
    measured: &[f64],
    lines: &[(&str, &[f64])],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let pts = |v: &[f64]| -> Vec<(f64, f64)> {
        t.iter()
            .zip(v)
            .filter(|p| p.1.is_finite())
            .map(|(&a, &b)| (a, b))
            .collect()
    };
    let m = pts(measured);
    let (lo, hi) = m
        .iter()
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    if !(lo <= hi) || !(t0 < t1) {
        return Err(err(&"no finite measured samples to draw"));
    }
    let pad = 0.05 * (hi - lo).max(1e-12);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut c = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(70)
        .build_cartesian_2d(t0..t1, (lo - pad)..(hi + pad))
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::channel_label(channel))
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(m.iter().map(|&p| Circle::new(p, 1, BLACK.filled())))
        .map_err(|e| err(&e))?
        .label("measured")
        .legend(|(x, y)| Circle::new((x + 10, y), 2, BLACK.filled()));
    for (k, (name, v)) in lines.iter().enumerate() {
        let color = LINES[k % LINES.len()];
        c.draw_series(LineSeries::new(pts(v), color))
            .map_err(|e| err(&e))?
            .label(*name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
    }
    c.configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))
}
