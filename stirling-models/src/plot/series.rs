//! Measured against model over time, with the residual (measured - model) in a panel below:
//! the figures of `fit --plot` (per stage and channel, and the free run).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes;
use super::DrawError;

/// Finite `(lo, hi)` of `v` padded by 5 % (a unit band when flat).
fn span<'a>(v: impl Iterator<Item = &'a f64>) -> (f64, f64) {
    let (lo, hi) = v
        .copied()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    if !(lo <= hi) {
        return (-1.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-12 * hi.abs().max(1.0));
    (lo - pad, hi + pad)
}

/// The finite points `(t, v)`.
fn finite(t: &[f64], v: &[f64]) -> Vec<(f64, f64)> {
    t.iter()
        .copied()
        .zip(v.iter().copied())
        .filter(|p| p.1.is_finite())
        .collect()
}

/// Draw `measured` (dots) and `model` (line) of `channel` against `t` \[s\], the residual below.
pub fn measured_vs_model(
    path: &Path,
    title: &str,
    channel: &str,
    t: &[f64],
    measured: &[f64],
    model: &[f64],
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let (top, bottom) = root.split_vertically(360);
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(1.0),
    );
    let t1 = if t1 > t0 { t1 } else { t0 + 1.0 };
    let labels = (title, channel);
    values_panel(path, &top, labels, (t0, t1), (t, measured, model))?;
    let res: Vec<f64> = measured.iter().zip(model).map(|(m, s)| m - s).collect();
    residual_panel(path, &bottom, channel, (t0, t1), (t, &res))?;
    root.present().map_err(|x| e(&x))
}

/// The top panel: `measured` (grey dots) and `model` (red line) over `t0..t1`, a legend.
fn values_panel(
    path: &Path,
    top: &DrawingArea<SVGBackend, Shift>,
    (title, channel): (&str, &str),
    (t0, t1): (f64, f64),
    (t, measured, model): (&[f64], &[f64], &[f64]),
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let (lo, hi) = span(measured.iter().chain(model));
    let mut c = ChartBuilder::on(top)
        .caption(title, ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1, lo..hi)
        .map_err(|x| e(&x))?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::channel_label(channel))
        .draw()
        .map_err(|x| e(&x))?;
    let grey = RGBColor(120, 120, 120);
    c.draw_series(
        finite(t, measured)
            .into_iter()
            .map(|p| Circle::new(p, 1, grey.filled())),
    )
    .map_err(|x| e(&x))?
    .label("measured")
    .legend(move |(x, y)| Circle::new((x + 10, y), 3, grey.filled()));
    c.draw_series(LineSeries::new(finite(t, model), RED.stroke_width(2)))
        .map_err(|x| e(&x))?
        .label("model")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
    c.configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.7))
        .border_style(BLACK)
        .draw()
        .map_err(|x| e(&x))?;
    Ok(())
}

/// The bottom panel: the residual `res` (blue dots) around a zero line, symmetric range.
fn residual_panel(
    path: &Path,
    bottom: &DrawingArea<SVGBackend, Shift>,
    channel: &str,
    (t0, t1): (f64, f64),
    (t, res): (&[f64], &[f64]),
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let (r0, r1) = span(res.iter());
    let r = r0.abs().max(r1.abs());
    let mut c = ChartBuilder::on(bottom)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(80)
        .build_cartesian_2d(t0..t1, -r..r)
        .map_err(|x| e(&x))?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::label("residual", axes::channel_unit(channel)))
        .draw()
        .map_err(|x| e(&x))?;
    c.draw_series(LineSeries::new([(t0, 0.0), (t1, 0.0)], BLACK.mix(0.5)))
        .map_err(|x| e(&x))?;
    c.draw_series(
        finite(t, res)
            .into_iter()
            .map(|p| Circle::new(p, 1, BLUE.filled())),
    )
    .map_err(|x| e(&x))?;
    Ok(())
}
