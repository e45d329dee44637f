//! Root locus: the poles at every parameter value of a [`Locus`](crate::linear::Locus), coloured
//! from blue (first value) to red (last) with a colour bar giving the parameter and its unit; the
//! right half plane shaded as in the pole map; where the number of right-half-plane poles changes
//! (the stability crossing) the poles of the first value past it are ringed and the value named.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::axes;
use super::poles::{frame, splane_chart};
use super::DrawError;
use crate::linear::Locus;

/// The colour of the fraction `t` in [0, 1] of the range.
fn color(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    RGBColor((255.0 * t) as u8, 0, (255.0 * (1.0 - t)) as u8)
}

/// A parameter value with four significant digits.
fn fmt(v: f64) -> String {
    format!("{}", format!("{v:.4e}").parse::<f64>().unwrap_or(v))
}

/// The first index whose right-half-plane pole count differs from the one before.
fn crossing(locus: &Locus) -> Option<usize> {
    let rhp = |i: usize| locus.points[i].poles.iter().filter(|p| p.rhp).count();
    (1..locus.points.len()).find(|&i| rhp(i) != rhp(i - 1))
}

/// The title: model, parameter, the stability crossing `cross` if any, poles off frame.
fn title(locus: &Locus, unit: &str, cross: Option<usize>, out: usize) -> String {
    let mut title = format!("{}: root locus over {}", locus.model, locus.param);
    if let Some(i) = cross {
        let (a, b) = (locus.points[i - 1].value, locus.points[i].value);
        title.push_str(&format!(
            ", RHP count changes between {} and {} {unit} (ringed)",
            fmt(a),
            fmt(b)
        ));
    }
    if out > 0 {
        title.push_str(&format!(", {out} stiff poles off frame"));
    }
    title
}

/// Draw the root locus to an SVG file; `unit` is the parameter's unit (`-` if none).
pub fn root_locus(path: &Path, locus: &Locus, unit: &str) -> Result<(), DrawError> {
    let err = DrawError::at(path);
    let e = |x: &dyn std::fmt::Display| err(x.to_string());
    let unit = if unit.is_empty() { "-" } else { unit };
    let ((x0, x1, y1), out) = frame(locus.points.iter().flat_map(|p| p.poles.iter()));
    let root = SVGBackend::new(path, (920, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let (main, bar) = root.split_horizontally(790);
    let cross = crossing(locus);
    let title = title(locus, unit, cross, out);
    let mut chart = splane_chart(&main, title, 16, (x0, x1, y1), &err)?;
    let k = locus.points.len().max(2) - 1;
    for (i, pt) in locus.points.iter().enumerate() {
        let c = color(i as f64 / k as f64);
        let visible = pt.poles.iter().filter(|p| p.re >= x0 && p.im.abs() <= y1);
        chart
            .draw_series(visible.map(|p| Circle::new((p.re, p.im), 3, c.filled())))
            .map_err(|x| e(&x))?;
    }
    if let Some(i) = cross {
        let pt = &locus.points[i];
        chart
            .draw_series(
                pt.poles
                    .iter()
                    .filter(|p| p.re >= x0 && p.im.abs() <= y1)
                    .map(|p| Circle::new((p.re, p.im), 8, BLACK.stroke_width(2))),
            )
            .map_err(|x| e(&x))?;
    }
    color_bar(path, &bar, locus, unit)?;
    root.present().map_err(|x| e(&x))
}

/// The colour bar on `bar`: the parameter's values top (last) to bottom (first).
fn color_bar(
    path: &Path,
    bar: &DrawingArea<SVGBackend, Shift>,
    locus: &Locus,
    unit: &str,
) -> Result<(), DrawError> {
    let e = |x: &dyn std::fmt::Display| DrawError::on(path, x);
    let (first, last) = (
        locus.points.first().map_or(0.0, |p| p.value),
        locus.points.last().map_or(0.0, |p| p.value),
    );
    let (lo, hi) = if last > first {
        (first, last)
    } else if first > last {
        (last, first)
    } else {
        (first - 0.5, first + 0.5)
    };
    let mut cb = ChartBuilder::on(bar)
        .margin_top(45)
        .margin_bottom(60)
        .margin_left(20)
        .margin_right(5)
        .right_y_label_area_size(85)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(|x| e(&x))?;
    cb.configure_mesh()
        .disable_x_mesh()
        .disable_x_axis()
        .disable_y_mesh()
        .y_labels(6)
        .y_label_style(("sans-serif", 13))
        .y_label_formatter(&|v| fmt(*v))
        .axis_desc_style(("sans-serif", 14))
        .y_desc(axes::label(&locus.param, unit))
        .draw()
        .map_err(|x| e(&x))?;
    let steps = 100;
    cb.draw_series((0..steps).map(|j| {
        let (a, b) = (j as f64 / steps as f64, (j + 1) as f64 / steps as f64);
        let v = |t: f64| lo + (hi - lo) * t;
        // the colour follows the value from `first` to `last`
        let t = if (last - first).abs() > 0.0 {
            (v(a) - first) / (last - first)
        } else {
            0.0
        };
        Rectangle::new([(0.0, v(a)), (1.0, v(b))], color(t).filled())
    }))
    .map_err(|x| e(&x))?;
    Ok(())
}
