//! Start-up time response in the style of the seed's Figure 3: displacer `x`, piston `y`
//! \[mm\] and the pressures \[kPa\] against time \[s\], two stacked panels. The legends sit in a
//! strip right of the panels (they never hide a trace); the pressure traces are drawn from
//! wide and pale to narrow so that channels lying on top of each other stay visible.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{axes, DrawError};

/// The legend strip width [px].
const STRIP: u32 = 150;

/// One legend entry per `(name, colour, width)`, top to bottom, in `area`.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, RGBAColor, u32)],
) -> Result<(), String> {
    for (k, (name, color, width)) in entries.iter().enumerate() {
        let y = 40 + 22 * k as i32;
        area.draw(&PathElement::new(
            vec![(8, y), (36, y)],
            color.stroke_width(*width),
        ))
        .map_err(|e| e.to_string())?;
        area.draw(&Text::new(
            name.clone(),
            (42, y - 7),
            ("sans-serif", 13).into_font(),
        ))
        .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// A drawing area of the SVG figure.
type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;

/// Plot `x`, `y` (state columns `ix`, `iy`) and the `pressures` columns of `states` against `t`.
pub fn startup_svg(
    path: &Path,
    title: &str,
    t: &[f64],
    states: &[Vec<f64>],
    ix: usize,
    iy: usize,
    pressures: &[(String, usize)],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let root = SVGBackend::new(path, (900 + STRIP, 720)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let root = root
        .titled(&format!("{title}: start-up"), ("sans-serif", 20))
        .map_err(|e| err(&e))?;
    let (top, bottom) = root.split_vertically(340);
    let t1 = t.last().copied().unwrap_or(1.0).max(1e-12);
    let col = |k: usize, scale: f64| -> Vec<(f64, f64)> {
        t.iter()
            .zip(states)
            .filter_map(|(&t, x)| x.get(k).map(|v| (t, scale * v)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    positions_panel(path, &top, t1, (col(ix, 1e3), col(iy, 1e3)))?;
    let series: Vec<Vec<(f64, f64)>> = pressures.iter().map(|(_, k)| col(*k, 1e-3)).collect();
    pressure_panel(path, &bottom, t1, series, pressures)?;
    root.present().map_err(|e| err(&e))
}

/// The top panel (with its legend strip): `x` and `y` \[mm\] over `0..t1`.
fn positions_panel(
    path: &Path,
    top: &Area,
    t1: f64,
    (xs, ys): (Vec<(f64, f64)>, Vec<(f64, f64)>),
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let (top, top_strip) = top.split_horizontally(900);
    let lim = xs.iter().chain(&ys).map(|p| p.1.abs()).fold(1e-9, f64::max) * 1.05;
    let mut c = ChartBuilder::on(&top)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, -lim..lim)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::label("position", "mm"))
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(xs, BLUE.stroke_width(2)))
        .map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(ys, RED.stroke_width(1)))
        .map_err(|e| err(&e))?;
    legend(
        &top_strip,
        &[
            ("displacer x".into(), BLUE.to_rgba(), 2),
            ("piston y".into(), RED.to_rgba(), 1),
        ],
    )
    .map_err(|e| err(&e))
}

/// The pressure axis range: the traces' span padded by 5 % (a flat trace: +-1 kPa).
fn pressure_range(series: &[Vec<(f64, f64)>]) -> (f64, f64) {
    let (lo, hi) = series
        .iter()
        .flatten()
        .fold((f64::MAX, f64::MIN), |(l, h), p| (l.min(p.1), h.max(p.1)));
    if lo < hi {
        (lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
    } else if lo == hi {
        (lo - 1.0, lo + 1.0)
    } else {
        (0.0, 1.0)
    }
}

/// The bottom panel (with its legend strip): the pressure traces \[kPa\] over `0..t1`.
fn pressure_panel(
    path: &Path,
    bottom: &Area,
    t1: f64,
    series: Vec<Vec<(f64, f64)>>,
    pressures: &[(String, usize)],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let (bottom, bottom_strip) = bottom.split_horizontally(900);
    let (lo, hi) = pressure_range(&series);
    let mut c = ChartBuilder::on(&bottom)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, lo..hi)
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("t", "s"))
        .y_desc(axes::label("pressure", "kPa"))
        .draw()
        .map_err(|e| err(&e))?;
    let k = series.len();
    let mut entries = Vec::new();
    for (i, (s, (name, _))) in series.into_iter().zip(pressures).enumerate() {
        let color = Palette99::pick(i).to_rgba();
        // The first trace widest and palest, the last one 1 px: overlaps stay visible.
        let width = 1 + 2 * (k - 1 - i) as u32;
        let color = color.mix(if i + 1 == k { 1.0 } else { 0.6 });
        c.draw_series(LineSeries::new(s, color.stroke_width(width)))
            .map_err(|e| err(&e))?;
        entries.push((name.clone(), color, width));
    }
    legend(&bottom_strip, &entries).map_err(|e| err(&e))
}
