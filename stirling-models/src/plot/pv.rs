//! PV diagram per vessel over one cycle: pressure \[kPa\] against volume \[cm^3\]; the enclosed
//! area is the vessel's cycle work, arrowheads along the loop show the direction of the cycle
//! (clockwise: work done by the gas), a dot marks its start.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{axes, DrawError};

/// A drawing area of the SVG figure.
type Area<'b> = DrawingArea<SVGBackend<'b>, Shift>;

/// One closed `(V, P)` loop per vessel, in one panel each (a grid).
pub fn pv_svg(
    path: &Path,
    title: &str,
    vessels: &[String],
    loops: &[Vec<(f64, f64)>],
    work: &[f64],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let k = vessels.len().max(1);
    let cols = k.min(3);
    let rows = k.div_ceil(cols);
    let canvas =
        SVGBackend::new(path, (360 * cols as u32, 320 * rows as u32 + 40)).into_drawing_area();
    canvas.fill(&WHITE).map_err(|e| err(&e))?;
    let root = canvas
        .titled(&format!("{title}: PV diagrams"), ("sans-serif", 20))
        .map_err(|e| err(&e))?;
    for (i, area) in root
        .split_evenly((rows, cols))
        .into_iter()
        .enumerate()
        .take(vessels.len())
    {
        let pts: Vec<(f64, f64)> = loops[i].iter().map(|&(v, p)| (1e6 * v, 1e-3 * p)).collect();
        let caption = format!(
            "{} (W = {:.4} J)",
            vessels[i],
            work.get(i).copied().unwrap_or(0.0)
        );
        vessel_panel(path, (&canvas, &area), &caption, &pts)?;
    }
    root.present().map_err(|e| err(&e))
}

/// The axis range of the loop's coordinate `f`, padded (a constant one gets a 2 % band).
fn span(pts: &[(f64, f64)], f: fn(&(f64, f64)) -> f64) -> std::ops::Range<f64> {
    let (l, h) = pts
        .iter()
        .map(f)
        .fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    // A vessel of constant volume or pressure gets a band of 2 % around its value.
    let pad = ((h - l) * 0.05).max(0.02 * h.abs()).max(1e-9);
    (l - pad)..(h + pad)
}

/// One vessel's panel on `area`: the loop `pts` [cm^3, kPa], its start, the arrowheads
/// (drawn on the whole `canvas`).
fn vessel_panel(
    path: &Path,
    (canvas, area): (&Area, &Area),
    caption: &str,
    pts: &[(f64, f64)],
) -> Result<(), DrawError> {
    let err = |e: &dyn std::fmt::Display| DrawError::on(path, e);
    let mut c = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 14))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(60)
        .build_cartesian_2d(span(pts, |p| p.0), span(pts, |p| p.1))
        .map_err(|e| err(&e))?;
    c.configure_mesh()
        .x_desc(axes::label("V", "cm^3"))
        .y_desc(axes::label("P", "kPa"))
        .x_labels(5)
        .draw()
        .map_err(|e| err(&e))?;
    c.draw_series(LineSeries::new(pts.to_vec(), &BLUE))
        .map_err(|e| err(&e))?;
    if let Some(&p0) = pts.first() {
        c.draw_series(std::iter::once(Circle::new(p0, 4, BLUE.filled())))
            .map_err(|e| err(&e))?;
    }
    // Arrowheads in pixels (the axes are scaled differently), drawn on the whole canvas.
    let m = pts.len();
    for j in 0..4 {
        let i = j * m / 4 + m / 8;
        let (Some(&a), Some(&b)) = (pts.get(i), pts.get((i + 2).min(m.saturating_sub(1)))) else {
            continue;
        };
        let Some(head) = arrowhead(c.backend_coord(&a), c.backend_coord(&b)) else {
            continue;
        };
        canvas
            .draw(&Polygon::new(head, BLUE.filled()))
            .map_err(|e| err(&e))?;
    }
    Ok(())
}

/// The triangle of an arrowhead at pixel `pa` pointing towards `pb` (none if they coincide).
pub(super) fn arrowhead(pa: (i32, i32), pb: (i32, i32)) -> Option<Vec<(i32, i32)>> {
    let (dx, dy) = ((pb.0 - pa.0) as f64, (pb.1 - pa.1) as f64);
    let len = dx.hypot(dy);
    if len < 1e-9 {
        return None;
    }
    let (ux, uy) = (dx / len, dy / len);
    let tip = (pa.0 as f64 + 5.0 * ux, pa.1 as f64 + 5.0 * uy);
    let back = (tip.0 - 11.0 * ux, tip.1 - 11.0 * uy);
    let px = |x: f64, y: f64| (x.round() as i32, y.round() as i32);
    Some(vec![
        px(tip.0, tip.1),
        px(back.0 - 5.0 * uy, back.1 + 5.0 * ux),
        px(back.0 + 5.0 * uy, back.1 - 5.0 * ux),
    ])
}
